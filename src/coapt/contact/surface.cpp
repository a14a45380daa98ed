/// @file surface.cpp
/// Gathering contact surfaces on every rank, their boundary nodes and averaged normals.

#include "coapt/contact/surface.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include "coapt/core/error.hpp"

namespace coapt::contact {

namespace {

/// Concatenates `local` over the ranks of `comm` (rank order) on every rank.
template <class T>
std::vector<T> all_gather(const std::vector<T>& local, MPI_Datatype type, MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  const int n = static_cast<int>(local.size());
  std::vector<int> counts(static_cast<std::size_t>(size)), offsets(static_cast<std::size_t>(size));
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  std::exclusive_scan(counts.begin(), counts.end(), offsets.begin(), 0);
  std::vector<T> all(static_cast<std::size_t>(offsets.back() + counts.back()));
  MPI_Allgatherv(local.data(), n, type, all.data(), counts.data(), offsets.data(), type, comm);
  return all;
}

}  // namespace

Surface gather_surface(const mesh::Mesh& mesh, std::span<const int> tags, std::string name) {
  const int dim = mesh.dim;
  // Facets of owned cells only: each boundary facet bounds one cell, owned by one rank.
  std::vector<PetscInt> global;
  std::vector<std::int64_t> keys;
  std::vector<double> coordinates;
  for (int f = 0; f < mesh.n_facets(); ++f) {
    if (mesh.facet_cell[f] >= mesh.n_owned_cells) continue;
    if (std::find(tags.begin(), tags.end(), mesh.facet_tags[f]) == tags.end()) continue;
    for (int k = 0; k < dim; ++k) {
      const int v = mesh.facets[static_cast<std::size_t>(f) * dim + k];
      global.push_back(mesh.global_vertex[v]);
      keys.push_back(mesh.original_vertex.empty() ? mesh.global_vertex[v]
                                                  : mesh.original_vertex[v]);
      for (int i = 0; i < dim; ++i) coordinates.push_back(mesh.point(v)[i]);
    }
  }
  const auto all_global = all_gather(global, MPIU_INT, mesh.comm);
  const auto all_keys = all_gather(keys, MPI_INT64_T, mesh.comm);
  const auto all_coordinates = all_gather(coordinates, MPI_DOUBLE, mesh.comm);

  Surface surface;
  surface.dim = dim;
  surface.name = std::move(name);
  // Nodes sorted by source number.
  std::map<std::int64_t, int> node_of_key;
  for (std::size_t k = 0; k < all_keys.size(); ++k) node_of_key.emplace(all_keys[k], -1);
  int n_nodes = 0;
  for (auto& [key, node] : node_of_key) node = n_nodes++;
  surface.global_vertex.resize(static_cast<std::size_t>(n_nodes));
  surface.key.resize(static_cast<std::size_t>(n_nodes));
  surface.reference.resize(static_cast<std::size_t>(n_nodes) * dim);
  for (std::size_t k = 0; k < all_keys.size(); ++k) {
    const int node = node_of_key[all_keys[k]];
    surface.global_vertex[node] = all_global[k];
    surface.key[node] = all_keys[k];
    for (int i = 0; i < dim; ++i)
      surface.reference[static_cast<std::size_t>(node) * dim + i] = all_coordinates[k * dim + i];
  }
  // Facets sorted by their node tuples (orientation kept).
  const std::size_t n_facets = all_keys.size() / static_cast<std::size_t>(dim);
  std::vector<std::vector<int>> facets(n_facets);
  for (std::size_t f = 0; f < n_facets; ++f)
    for (int k = 0; k < dim; ++k) facets[f].push_back(node_of_key[all_keys[f * dim + k]]);
  std::sort(facets.begin(), facets.end());
  for (const auto& facet : facets)
    surface.facets.insert(surface.facets.end(), facet.begin(), facet.end());
  return surface;
}

Surface make_surface(int dim, std::vector<double> coordinates, std::vector<int> facets) {
  if (dim != 2 && dim != 3) throw InternalError("make_surface: dimension must be 2 or 3");
  Surface surface;
  surface.dim = dim;
  surface.name = "surface";
  surface.reference = std::move(coordinates);
  surface.facets = std::move(facets);
  const std::size_t n = surface.reference.size() / static_cast<std::size_t>(dim);
  surface.global_vertex.resize(n);
  surface.key.resize(n);
  std::iota(surface.global_vertex.begin(), surface.global_vertex.end(), 0);
  std::iota(surface.key.begin(), surface.key.end(), 0);
  return surface;
}

std::vector<char> boundary_nodes(const Surface& surface) {
  std::vector<char> boundary(static_cast<std::size_t>(surface.n_nodes()), 0);
  if (surface.dim == 2) {
    std::vector<int> count(static_cast<std::size_t>(surface.n_nodes()), 0);
    for (int node : surface.facets) ++count[node];
    for (int n = 0; n < surface.n_nodes(); ++n) boundary[n] = count[n] == 1;
    return boundary;
  }
  std::map<std::pair<int, int>, int> edges;
  for (int f = 0; f < surface.n_facets(); ++f) {
    const auto v = surface.facet(f);
    for (int k = 0; k < 3; ++k) {
      const int a = v[k], b = v[(k + 1) % 3];
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  }
  for (const auto& [edge, count] : edges)
    if (count == 1) boundary[edge.first] = boundary[edge.second] = 1;
  return boundary;
}

std::array<double, 3> facet_area_normal(const Surface& surface, std::span<const double> x, int f) {
  const int dim = surface.dim;
  const auto v = surface.facet(f);
  const double* a = x.data() + static_cast<std::size_t>(v[0]) * dim;
  const double* b = x.data() + static_cast<std::size_t>(v[1]) * dim;
  if (dim == 2) return {b[1] - a[1], -(b[0] - a[0]), 0.0};
  const double* c = x.data() + static_cast<std::size_t>(v[2]) * dim;
  const double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double g[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {0.5 * (e[1] * g[2] - e[2] * g[1]), 0.5 * (e[2] * g[0] - e[0] * g[2]),
          0.5 * (e[0] * g[1] - e[1] * g[0])};
}

std::vector<double> nodal_measures(const Surface& surface, std::span<const double> x) {
  std::vector<double> measures(static_cast<std::size_t>(surface.n_nodes()), 0.0);
  for (int f = 0; f < surface.n_facets(); ++f) {
    const auto a = facet_area_normal(surface, x, f);
    const double share = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) / surface.dim;
    for (const int node : surface.facet(f)) measures[static_cast<std::size_t>(node)] += share;
  }
  return measures;
}

std::vector<double> nodal_normals(const Surface& surface, std::span<const double> x,
                                  std::vector<char>* valid, double min_alignment) {
  const int dim = surface.dim;
  const std::size_t n = static_cast<std::size_t>(surface.n_nodes());
  std::vector<double> normals(n * dim, 0.0), area(n, 0.0);
  for (int f = 0; f < surface.n_facets(); ++f) {
    const auto a = facet_area_normal(surface, x, f);
    const double measure = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int node : surface.facet(f)) {
      for (int i = 0; i < dim; ++i) normals[static_cast<std::size_t>(node) * dim + i] += a[i];
      area[node] += measure;
    }
  }
  if (valid) valid->assign(n, 1);
  for (std::size_t node = 0; node < n; ++node) {
    double norm = 0.0;
    for (int i = 0; i < dim; ++i) norm += normals[node * dim + i] * normals[node * dim + i];
    norm = std::sqrt(norm);
    const bool ok = area[node] > 0.0 && norm >= min_alignment * area[node];
    for (int i = 0; i < dim; ++i)
      normals[node * dim + i] = ok ? normals[node * dim + i] / norm : 0.0;
    if (valid) (*valid)[node] = ok;
  }
  return normals;
}

SurfaceGather::SurfaceGather(const Surface& surface, Vec layout) : dim_(surface.dim) {
  const PetscInt n = static_cast<PetscInt>(surface.n_nodes()) * dim_;
  std::vector<PetscInt> dofs(static_cast<std::size_t>(n));
  for (int node = 0; node < surface.n_nodes(); ++node)
    for (int i = 0; i < dim_; ++i)
      dofs[static_cast<std::size_t>(node) * dim_ + i] = surface.global_vertex[node] * dim_ + i;
  COAPT_PETSC_CHECK(VecCreateSeq(PETSC_COMM_SELF, n, local_.out()));
  IS from = nullptr;
  COAPT_PETSC_CHECK(ISCreateGeneral(PETSC_COMM_SELF, n, dofs.data(), PETSC_COPY_VALUES, &from));
  OwnedIS owned_from(from);
  COAPT_PETSC_CHECK(VecScatterCreate(layout, from, local_, nullptr, scatter_.out()));
}

void SurfaceGather::gather(Vec vector, std::vector<double>& values) const {
  COAPT_PETSC_CHECK(VecScatterBegin(scatter_, vector, local_, INSERT_VALUES, SCATTER_FORWARD));
  COAPT_PETSC_CHECK(VecScatterEnd(scatter_, vector, local_, INSERT_VALUES, SCATTER_FORWARD));
  PetscInt n = 0;
  COAPT_PETSC_CHECK(VecGetLocalSize(local_, &n));
  const PetscScalar* data = nullptr;
  COAPT_PETSC_CHECK(VecGetArrayRead(local_, &data));
  values.assign(data, data + n);
  COAPT_PETSC_CHECK(VecRestoreArrayRead(local_, &data));
}

}  // namespace coapt::contact
