#pragma once
/// @file assembly.hpp
/// Parallel assembly of P1 systems into PETSc: matrices through PETSc's COO interface (the
/// pattern is computed once from the owned cells, so re-assembly only writes values, with
/// exact preallocation), vectors through ghosted local forms, and Dirichlet conditions that
/// keep symmetric systems symmetric.
///
/// Degrees of freedom are interleaved: dof (vertex v, component i) has the global number
/// global_vertex[v] * n_components + i, so a rank owns a contiguous range of rows.

#include <petscmat.h>
#include <petscvec.h>

#include <span>
#include <vector>

#include "coapt/core/petsc.hpp"
#include "coapt/mesh/mesh.hpp"

namespace coapt::fem {

/// A ghosted PETSc vector over the vertices of `mesh` with `n_components` per vertex; its
/// local form is ordered as the mesh's local vertices (owned, then ghosts). Collective.
OwnedVec create_vertex_vector(const mesh::Mesh& mesh, int n_components);

/// Refreshes the ghost entries of a vector from create_vertex_vector. Collective.
void update_ghosts(Vec vector);

/// Read access to the local form (owned + ghost entries) of a ghosted vector.
class LocalValues {
 public:
  explicit LocalValues(Vec vector);
  LocalValues(const LocalValues&) = delete;
  LocalValues& operator=(const LocalValues&) = delete;
  ~LocalValues();
  std::span<const PetscScalar> values() const { return {data_, static_cast<std::size_t>(size_)}; }
  const PetscScalar& operator[](std::size_t i) const { return data_[i]; }

 private:
  Vec vector_ = nullptr;
  Vec local_ = nullptr;
  const PetscScalar* data_ = nullptr;
  PetscInt size_ = 0;
};

/// An MPIAIJ matrix over the P1 dofs of a mesh, assembled cell by cell over the owned cells.
class P1Matrix {
 public:
  /// Creates the matrix and its COO pattern (collective on mesh.comm). `mesh` must outlive it.
  P1Matrix(const mesh::Mesh& mesh, int n_components);

  /// Assembles: `kernel(c, element_matrix)` writes the (k·n)×(k·n) row-major element matrix of
  /// owned cell c (k = dim + 1 vertices, n components, node-major dofs a·n + i). Collective.
  template <class Kernel>
  void assemble(Kernel&& kernel) {
    const std::size_t block = static_cast<std::size_t>(element_size_) * element_size_;
    for (int c = 0; c < mesh_.n_owned_cells; ++c) kernel(c, values_.data() + c * block);
    finish_assembly();
  }
  Mat mat() const { return matrix_.get(); }
  int n_components() const { return n_components_; }

 private:
  void finish_assembly();
  const mesh::Mesh& mesh_;
  int n_components_;
  int element_size_;
  OwnedMat matrix_;
  std::vector<PetscScalar> values_;
};

/// Assembles a vector: `kernel(c, element_vector)` writes the k·n entries of owned cell c,
/// added into `vector` (from create_vertex_vector; it is zeroed first). Collective.
template <class Kernel>
void assemble_vector(const mesh::Mesh& mesh, int n_components, Vec vector, Kernel&& kernel);

/// Global dofs (this rank's owned ones only) of the vertices on facets tagged `tag`, for the
/// given components (all when empty). Sorted, unique.
std::vector<PetscInt> boundary_dofs(const mesh::Mesh& mesh, int n_components, int tag,
                                    std::span<const int> components = {});

/// Imposes u = values on `dofs` in A x = b symmetrically: rows and columns of the dofs are
/// zeroed, the diagonal set to the mean diagonal (keeps the scaling), b corrected by the
/// removed columns. `values` is a vector with the boundary values at those dofs. Collective.
void apply_dirichlet(Mat matrix, Vec rhs, std::span<const PetscInt> dofs, Vec values);

// ---------------------------------------------------------------------------------------

void add_local_to_global(Vec vector);  // reverse ghost scatter with ADD (internal helper)

template <class Kernel>
void assemble_vector(const mesh::Mesh& mesh, int n_components, Vec vector, Kernel&& kernel) {
  Vec local = nullptr;
  VecGhostGetLocalForm(vector, &local);
  VecSet(local, 0.0);
  PetscScalar* data = nullptr;
  VecGetArray(local, &data);
  const int k = mesh.vertices_per_cell();
  std::vector<PetscScalar> element(static_cast<std::size_t>(k) * n_components);
  for (int c = 0; c < mesh.n_owned_cells; ++c) {
    std::fill(element.begin(), element.end(), 0.0);
    kernel(c, element.data());
    const auto vertices = mesh.cell(c);
    for (int a = 0; a < k; ++a)
      for (int i = 0; i < n_components; ++i)
        data[static_cast<std::size_t>(vertices[a]) * n_components + i] += element[a * n_components + i];
  }
  VecRestoreArray(local, &data);
  VecGhostRestoreLocalForm(vector, &local);
  add_local_to_global(vector);
}

}  // namespace coapt::fem
