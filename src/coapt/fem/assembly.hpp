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

/// A ghosted PETSc vector with one entry per cell of `mesh`; its local form is ordered as the
/// mesh's local cells (owned, then ghosts; mesh::Mesh::global_cell). Collective.
OwnedVec create_cell_vector(const mesh::Mesh& mesh);

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

/// An MPIAIJ matrix over the P1 dofs of a mesh. Each rank assembles its own rows completely
/// from its local cells (owned and ghost: the ghost layer holds every cell touching an owned
/// vertex), so assembly needs no communication; the CSR pattern and, for every cell, the
/// positions of its entries in that pattern are computed once, and re-assembly writes values
/// straight into the CSR array handed to PETSc (MatUpdateMPIAIJWithArray).
class P1Matrix {
 public:
  /// Creates the matrix (all zero) and its pattern. Collective on mesh.comm. `mesh` must
  /// outlive the matrix and keep its connectivity.
  P1Matrix(const mesh::Mesh& mesh, int n_components);

  /// Assembles: `kernel(c, element_matrix)` writes the (k·n)×(k·n) row-major element matrix of
  /// local cell c (k = dim + 1 vertices, n components, node-major dofs a·n + i). It is called
  /// for every local cell with an owned vertex, ghost cells included. Collective.
  template <class Kernel>
  void assemble(Kernel&& kernel) {
    std::fill(values_.begin(), values_.end(), 0.0);
    const std::size_t k = static_cast<std::size_t>(mesh_.vertices_per_cell());
    for (std::size_t index = 0; index < cells_.size(); ++index) {
      kernel(cells_[index], element_.data());
      add_element(index, k);
    }
    finish_assembly();
  }
  Mat mat() const { return matrix_.get(); }
  int n_components() const { return n_components_; }

 private:
  void add_element(std::size_t index, std::size_t k) {
    const int n = n_components_;
    const int* slots = slots_.data() + index * k * k;
    const int* vertices = mesh_.cell(cells_[index]).data();
    const std::size_t row_size = k * n;
    for (std::size_t a = 0; a < k; ++a) {
      const int v = vertices[a];
      if (v >= mesh_.n_owned_vertices) continue;
      const PetscInt degree = node_offsets_[v + 1] - node_offsets_[v];
      PetscScalar* block = values_.data() + static_cast<std::size_t>(node_offsets_[v]) * n * n;
      for (int i = 0; i < n; ++i) {
        PetscScalar* row = block + static_cast<std::size_t>(i) * degree * n;
        const PetscScalar* element_row = element_.data() + (a * n + i) * row_size;
        for (std::size_t b = 0; b < k; ++b) {
          PetscScalar* target = row + static_cast<std::size_t>(slots[a * k + b]) * n;
          for (int j = 0; j < n; ++j) target[j] += element_row[b * n + j];
        }
      }
    }
  }
  void finish_assembly();

  const mesh::Mesh& mesh_;
  int n_components_;
  std::vector<int> cells_;              ///< local cells with an owned vertex
  std::vector<PetscInt> node_offsets_;  ///< CSR of the owned vertices' neighbours (n_owned + 1)
  std::vector<int> slots_;              ///< per cell, k×k: position of b in a's neighbours
  std::vector<PetscScalar> values_;     ///< CSR values of the owned dof rows
  std::vector<PetscScalar> element_;    ///< element matrix buffer
  OwnedMat matrix_;
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

/// Gives `matrix` (a vector problem with mesh.dim components per vertex) the rigid-body modes
/// of the mesh as its near-null space (3 in 2D, 6 in 3D), which GAMG uses. Collective.
void set_rigid_body_modes(const mesh::Mesh& mesh, Mat matrix);

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
        data[static_cast<std::size_t>(vertices[a]) * n_components + i] +=
            element[a * n_components + i];
  }
  VecRestoreArray(local, &data);
  VecGhostRestoreLocalForm(vector, &local);
  add_local_to_global(vector);
}

}  // namespace coapt::fem
