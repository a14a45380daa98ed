#include "coapt/fem/assembly.hpp"

#include <algorithm>

#include "coapt/core/error.hpp"

namespace coapt::fem {

OwnedVec create_vertex_vector(const mesh::Mesh& mesh, int n_components) {
  const int n_ghosts = mesh.n_vertices() - mesh.n_owned_vertices;
  std::vector<PetscInt> ghosts(mesh.global_vertex.begin() + mesh.n_owned_vertices,
                               mesh.global_vertex.end());
  OwnedVec vector;
  COAPT_PETSC_CHECK(VecCreateGhostBlock(mesh.comm, n_components,
                                        static_cast<PetscInt>(mesh.n_owned_vertices) * n_components,
                                        PETSC_DECIDE, n_ghosts, ghosts.data(), vector.out()));
  COAPT_PETSC_CHECK(VecSet(vector, 0.0));
  return vector;
}

void update_ghosts(Vec vector) {
  COAPT_PETSC_CHECK(VecGhostUpdateBegin(vector, INSERT_VALUES, SCATTER_FORWARD));
  COAPT_PETSC_CHECK(VecGhostUpdateEnd(vector, INSERT_VALUES, SCATTER_FORWARD));
}

void add_local_to_global(Vec vector) {
  COAPT_PETSC_CHECK(VecGhostUpdateBegin(vector, ADD_VALUES, SCATTER_REVERSE));
  COAPT_PETSC_CHECK(VecGhostUpdateEnd(vector, ADD_VALUES, SCATTER_REVERSE));
  update_ghosts(vector);
}

LocalValues::LocalValues(Vec vector) : vector_(vector) {
  COAPT_PETSC_CHECK(VecGhostGetLocalForm(vector_, &local_));
  COAPT_PETSC_CHECK(VecGetLocalSize(local_, &size_));
  COAPT_PETSC_CHECK(VecGetArrayRead(local_, &data_));
}

LocalValues::~LocalValues() {
  VecRestoreArrayRead(local_, &data_);
  VecGhostRestoreLocalForm(vector_, &local_);
}

P1Matrix::P1Matrix(const mesh::Mesh& mesh, int n_components)
    : mesh_(mesh), n_components_(n_components), element_size_(mesh.vertices_per_cell() * n_components) {
  const PetscInt n_local = static_cast<PetscInt>(mesh.n_owned_vertices) * n_components;
  COAPT_PETSC_CHECK(MatCreate(mesh.comm, matrix_.out()));
  COAPT_PETSC_CHECK(MatSetSizes(matrix_, n_local, n_local, PETSC_DETERMINE, PETSC_DETERMINE));
  COAPT_PETSC_CHECK(MatSetType(matrix_, MATAIJ));
  COAPT_PETSC_CHECK(MatSetBlockSize(matrix_, n_components));

  // The COO pattern: every entry of every owned cell's element matrix, in element order.
  const std::size_t block = static_cast<std::size_t>(element_size_) * element_size_;
  const std::size_t n_entries = static_cast<std::size_t>(mesh.n_owned_cells) * block;
  std::vector<PetscInt> rows(n_entries), columns(n_entries);
  std::vector<PetscInt> dofs(static_cast<std::size_t>(element_size_));
  const int k = mesh.vertices_per_cell();
  for (int c = 0; c < mesh.n_owned_cells; ++c) {
    const auto vertices = mesh.cell(c);
    for (int a = 0; a < k; ++a)
      for (int i = 0; i < n_components; ++i)
        dofs[a * n_components + i] = mesh.global_vertex[vertices[a]] * n_components + i;
    PetscInt* r = rows.data() + c * block;
    PetscInt* s = columns.data() + c * block;
    for (int p = 0; p < element_size_; ++p)
      for (int q = 0; q < element_size_; ++q) {
        r[p * element_size_ + q] = dofs[p];
        s[p * element_size_ + q] = dofs[q];
      }
  }
  COAPT_PETSC_CHECK(MatSetPreallocationCOO(matrix_, static_cast<PetscCount>(n_entries), rows.data(),
                                           columns.data()));
  values_.assign(n_entries, 0.0);
}

void P1Matrix::finish_assembly() {
  COAPT_PETSC_CHECK(MatSetValuesCOO(matrix_, values_.data(), INSERT_VALUES));
}

std::vector<PetscInt> boundary_dofs(const mesh::Mesh& mesh, int n_components, int tag,
                                    std::span<const int> components) {
  std::vector<int> all(static_cast<std::size_t>(n_components));
  for (int i = 0; i < n_components; ++i) all[i] = i;
  if (components.empty()) components = all;
  std::vector<PetscInt> dofs;
  for (int f = 0; f < mesh.n_facets(); ++f) {
    if (mesh.facet_tags[f] != tag) continue;
    for (int a = 0; a < mesh.dim; ++a) {
      const int v = mesh.facets[static_cast<std::size_t>(f) * mesh.dim + a];
      if (v >= mesh.n_owned_vertices) continue;
      for (int i : components) dofs.push_back(mesh.global_vertex[v] * n_components + i);
    }
  }
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  return dofs;
}

void apply_dirichlet(Mat matrix, Vec rhs, std::span<const PetscInt> dofs, Vec values) {
  OwnedVec diagonal;
  COAPT_PETSC_CHECK(MatCreateVecs(matrix, diagonal.out(), nullptr));
  COAPT_PETSC_CHECK(MatGetDiagonal(matrix, diagonal));
  PetscReal sum = 0.0;
  PetscInt n = 0;
  COAPT_PETSC_CHECK(VecNorm(diagonal, NORM_1, &sum));
  COAPT_PETSC_CHECK(VecGetSize(diagonal, &n));
  const PetscScalar scale = n > 0 && sum > 0 ? sum / static_cast<PetscReal>(n) : 1.0;
  COAPT_PETSC_CHECK(MatZeroRowsColumns(matrix, static_cast<PetscInt>(dofs.size()), dofs.data(),
                                       scale, values, rhs));
}

}  // namespace coapt::fem
