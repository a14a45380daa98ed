#include "coapt/fem/assembly.hpp"

#include <algorithm>
#include <numeric>

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

OwnedVec create_cell_vector(const mesh::Mesh& mesh) {
  std::vector<PetscInt> ghosts;
  if (!mesh.global_cell.empty())
    ghosts.assign(mesh.global_cell.begin() + mesh.n_owned_cells, mesh.global_cell.end());
  else if (mesh.n_owned_cells != mesh.n_cells())
    throw InternalError("create_cell_vector: mesh '" + mesh.source +
                        "' has ghost cells but no global cell numbers");
  OwnedVec vector;
  COAPT_PETSC_CHECK(VecCreateGhost(mesh.comm, mesh.n_owned_cells, PETSC_DECIDE,
                                   static_cast<PetscInt>(ghosts.size()), ghosts.data(),
                                   vector.out()));
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
    : mesh_(mesh), n_components_(n_components) {
  const int k = mesh.vertices_per_cell(), n_owned = mesh.n_owned_vertices, n = n_components;
  // Local cells touching an owned vertex, and for each owned vertex the cells around it.
  std::vector<int> cells_of_vertex_count(static_cast<std::size_t>(n_owned) + 1, 0);
  for (int c = 0; c < mesh.n_cells(); ++c) {
    bool touches = false;
    for (int v : mesh.cell(c))
      if (v < n_owned) {
        touches = true;
        ++cells_of_vertex_count[static_cast<std::size_t>(v) + 1];
      }
    if (touches) cells_.push_back(c);
  }
  std::partial_sum(cells_of_vertex_count.begin(), cells_of_vertex_count.end(),
                   cells_of_vertex_count.begin());
  std::vector<int> cells_of_vertex(static_cast<std::size_t>(cells_of_vertex_count.back()));
  {
    std::vector<int> fill(cells_of_vertex_count.begin(), cells_of_vertex_count.end() - 1);
    for (int c : cells_)
      for (int v : mesh.cell(c))
        if (v < n_owned) cells_of_vertex[fill[v]++] = c;
  }
  // Neighbours of each owned vertex (local indices), sorted by global number: the node pattern.
  node_offsets_.assign(static_cast<std::size_t>(n_owned) + 1, 0);
  std::vector<int> neighbours;
  std::vector<int> buffer;
  for (int v = 0; v < n_owned; ++v) {
    buffer.clear();
    for (int i = cells_of_vertex_count[v]; i < cells_of_vertex_count[v + 1]; ++i)
      for (int w : mesh.cell(cells_of_vertex[i])) buffer.push_back(w);
    std::sort(buffer.begin(), buffer.end(),
              [&](int a, int b) { return mesh.global_vertex[a] < mesh.global_vertex[b]; });
    buffer.erase(std::unique(buffer.begin(), buffer.end()), buffer.end());
    neighbours.insert(neighbours.end(), buffer.begin(), buffer.end());
    node_offsets_[static_cast<std::size_t>(v) + 1] = static_cast<PetscInt>(neighbours.size());
  }
  // Each cell's entry (a, b), a owned: the position of b among a's neighbours.
  slots_.assign(cells_.size() * k * k, -1);
  for (std::size_t index = 0; index < cells_.size(); ++index) {
    const auto vertices = mesh.cell(cells_[index]);
    for (int a = 0; a < k; ++a) {
      const int v = vertices[a];
      if (v >= n_owned) continue;
      const auto first = neighbours.begin() + node_offsets_[v],
                 last = neighbours.begin() + node_offsets_[v + 1];
      for (int b = 0; b < k; ++b) {
        const PetscInt global = mesh.global_vertex[vertices[b]];
        const auto found = std::lower_bound(
            first, last, global, [&](int w, PetscInt g) { return mesh.global_vertex[w] < g; });
        slots_[index * k * k + static_cast<std::size_t>(a) * k + b] =
            static_cast<int>(found - first);
      }
    }
  }
  // The dof pattern: row (v, i) holds columns (w, j) for every neighbour w, every j, sorted.
  const std::size_t n_rows = static_cast<std::size_t>(n_owned) * n;
  std::vector<PetscInt> row_offsets(n_rows + 1, 0),
      columns(static_cast<std::size_t>(node_offsets_.back()) * n * n);
  for (int v = 0; v < n_owned; ++v) {
    const PetscInt degree = node_offsets_[v + 1] - node_offsets_[v];
    for (int i = 0; i < n; ++i) {
      const std::size_t row = static_cast<std::size_t>(v) * n + i;
      const PetscInt start = node_offsets_[v] * n * n + i * degree * n;
      row_offsets[row] = start;
      for (PetscInt m = 0; m < degree; ++m)
        for (int j = 0; j < n; ++j)
          columns[static_cast<std::size_t>(start + m * n + j)] =
              mesh.global_vertex[neighbours[node_offsets_[v] + m]] * n + j;
    }
  }
  row_offsets[n_rows] = static_cast<PetscInt>(columns.size());
  values_.assign(columns.size(), 0.0);
  element_.assign(static_cast<std::size_t>(k * n) * (k * n), 0.0);
  const PetscInt n_local = static_cast<PetscInt>(n_rows);
  COAPT_PETSC_CHECK(MatCreateMPIAIJWithArrays(mesh.comm, n_local, n_local, PETSC_DETERMINE,
                                              PETSC_DETERMINE, row_offsets.data(), columns.data(),
                                              values_.data(), matrix_.out()));
  COAPT_PETSC_CHECK(MatSetBlockSize(matrix_, n));
  COAPT_PETSC_CHECK(MatSetOption(matrix_, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE));
}

void P1Matrix::finish_assembly() {
  COAPT_PETSC_CHECK(MatUpdateMPIAIJWithArray(matrix_, values_.data()));
}

void set_rigid_body_modes(const mesh::Mesh& mesh, Mat matrix) {
  auto coordinates = create_vertex_vector(mesh, mesh.dim);
  PetscScalar* data = nullptr;
  COAPT_PETSC_CHECK(VecGetArray(coordinates, &data));
  std::copy_n(mesh.coordinates.begin(), static_cast<std::size_t>(mesh.n_owned_vertices) * mesh.dim,
              data);
  COAPT_PETSC_CHECK(VecRestoreArray(coordinates, &data));
  MatNullSpace null_space = nullptr;
  COAPT_PETSC_CHECK(MatNullSpaceCreateRigidBody(coordinates, &null_space));
  const PetscErrorCode status = MatSetNearNullSpace(matrix, null_space);
  MatNullSpaceDestroy(&null_space);
  COAPT_PETSC_CHECK(status);
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
