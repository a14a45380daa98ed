#include "coapt/mesh/topology.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <utility>

#include "coapt/core/error.hpp"

namespace coapt::mesh {
namespace {

// Outward-oriented local facets of a positively oriented simplex; facet f is opposite vertex f.
constexpr int kFacets2[3][2] = {{1, 2}, {2, 0}, {0, 1}};
constexpr int kFacets3[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

using Key = std::array<int, 3>;  // sorted facet vertices, padded with -1 in 2D

Key facet_key(int dim, const int* v) {
  if (dim == 2) return {std::min(v[0], v[1]), std::max(v[0], v[1]), -1};
  // Three-element sorting network.
  int a = std::min(v[0], v[1]), b = std::max(v[0], v[1]);
  const int c = std::max(b, v[2]);
  b = std::min(b, v[2]);
  return {std::min(a, b), std::max(a, b), c};
}

// Number of vertices referenced by the cells (max index + 1), checking the indices.
int referenced_vertices(const Mesh& mesh) {
  int n = 0;
  for (const int v : mesh.cells) {
    COAPT_ASSERT(v >= 0, "negative vertex index in the cells of " + mesh.source);
    n = std::max(n, v + 1);
  }
  return n;
}

}  // namespace

int local_facet_vertex(int dim, int f, int k) {
  return dim == 2 ? kFacets2[f][k] : kFacets3[f][k];
}

void orient_facet_outward(const Mesh& mesh, int cell, std::span<int> facet) {
  const int dim = mesh.dim;
  const auto vertices = mesh.cell(cell);
  int opposite = -1;
  for (const int v : vertices)
    if (std::find(facet.begin(), facet.end(), v) == facet.end()) opposite = v;
  if (opposite < 0) return;
  const double* points[4] = {};
  for (int k = 0; k < dim; ++k) points[k] = mesh.point(facet[k]).data();
  points[dim] = mesh.point(opposite).data();
  const double m = signed_measure(dim, points);
  // 2D: the cell (opposite vertex) must be on the left of a -> b: area(a, b, p) > 0.
  // 3D: the opposite vertex must be behind the outward normal: volume(a, b, c, p) < 0.
  if ((dim == 2 && m < 0) || (dim == 3 && m > 0)) std::swap(facet[dim - 2], facet[dim - 1]);
}

std::vector<int> boundary_facets(const Mesh& mesh, std::vector<int>* facet_cell) {
  const int dim = mesh.dim;
  COAPT_ASSERT(dim == 2 || dim == 3, "boundary_facets needs a 2D or 3D mesh");
  const int n_cells = mesh.n_cells();
  const int per_cell = dim + 1;
  const std::size_t n_faces = static_cast<std::size_t>(n_cells) * per_cell;
  const int n_vertices = referenced_vertices(mesh);

  // Bucket every cell facet by its smallest vertex (counting sort), keeping the other
  // (sorted) vertices and the facet id cell * (dim + 1) + f.
  struct Entry {
    int b, c, id;
  };
  std::vector<std::size_t> offset(static_cast<std::size_t>(n_vertices) + 1, 0);
  auto facet_of = [&](std::size_t id) {
    const int* cell = mesh.cells.data() + (id / per_cell) * per_cell;
    const int f = static_cast<int>(id % per_cell);
    int v[3] = {-1, -1, -1};
    for (int k = 0; k < dim; ++k) v[k] = cell[local_facet_vertex(dim, f, k)];
    return facet_key(dim, v);
  };
  for (std::size_t id = 0; id < n_faces; ++id) ++offset[facet_of(id)[0] + 1];
  for (int v = 0; v < n_vertices; ++v) offset[v + 1] += offset[v];
  std::vector<Entry> entries(n_faces);
  {
    std::vector<std::size_t> next(offset.begin(), offset.end() - 1);
    for (std::size_t id = 0; id < n_faces; ++id) {
      const Key key = facet_of(id);
      entries[next[key[0]]++] = {key[1], key[2], static_cast<int>(id)};
    }
  }
  std::vector<char> is_boundary(n_faces, 0);
  for (int v = 0; v < n_vertices; ++v) {
    const auto first = entries.begin() + static_cast<std::ptrdiff_t>(offset[v]);
    const auto last = entries.begin() + static_cast<std::ptrdiff_t>(offset[v + 1]);
    std::sort(first, last,
              [](const Entry& x, const Entry& y) { return x.b != y.b ? x.b < y.b : x.c < y.c; });
    for (auto it = first; it != last;) {
      auto run_end = it + 1;
      while (run_end != last && run_end->b == it->b && run_end->c == it->c) ++run_end;
      if (run_end - it == 1) is_boundary[static_cast<std::size_t>(it->id)] = 1;
      it = run_end;
    }
  }

  std::vector<int> facets;
  if (facet_cell) facet_cell->clear();
  for (std::size_t id = 0; id < n_faces; ++id) {
    if (!is_boundary[id]) continue;
    const int cell = static_cast<int>(id / per_cell);
    const int f = static_cast<int>(id % per_cell);
    const auto vertices = mesh.cell(cell);
    const std::size_t start = facets.size();
    for (int k = 0; k < dim; ++k) facets.push_back(vertices[local_facet_vertex(dim, f, k)]);
    // The local facet table is outward for positive cells; check geometrically for others.
    if (cell_signed_measure(mesh, cell) < 0)
      orient_facet_outward(mesh, cell, std::span<int>(facets.data() + start, dim));
    if (facet_cell) facet_cell->push_back(cell);
  }
  return facets;
}

std::vector<int> find_facet_cells(const Mesh& mesh, std::span<const int> facets) {
  const int dim = mesh.dim;
  COAPT_ASSERT(dim == 2 || dim == 3, "find_facet_cells needs a 2D or 3D mesh");
  COAPT_ASSERT(facets.size() % dim == 0, "facet array size is not a multiple of dim");
  const std::size_t n_facets = facets.size() / dim;
  std::vector<int> result(n_facets, -1);
  if (n_facets == 0) return result;
  const int n_vertices = referenced_vertices(mesh);

  // Sorted (key, facet) list, and a mark on every vertex some facet uses.
  std::vector<std::pair<Key, int>> sorted;
  sorted.reserve(n_facets);
  std::vector<char> in_facet(static_cast<std::size_t>(n_vertices), 0);
  for (std::size_t i = 0; i < n_facets; ++i) {
    const int* v = facets.data() + i * dim;
    bool valid = true;
    for (int k = 0; k < dim; ++k) valid = valid && v[k] >= 0 && v[k] < n_vertices;
    if (!valid) continue;
    for (int k = 0; k < dim; ++k) in_facet[static_cast<std::size_t>(v[k])] = 1;
    sorted.emplace_back(facet_key(dim, v), static_cast<int>(i));
  }
  std::sort(sorted.begin(), sorted.end());

  const int n_cells = mesh.n_cells();
  for (int cell = 0; cell < n_cells; ++cell) {
    const auto vertices = mesh.cell(cell);
    for (int f = 0; f <= dim; ++f) {
      int v[3] = {-1, -1, -1};
      bool candidate = true;
      for (int k = 0; k < dim; ++k) {
        v[k] = vertices[local_facet_vertex(dim, f, k)];
        candidate = candidate && in_facet[static_cast<std::size_t>(v[k])];
      }
      if (!candidate) continue;
      const Key key = facet_key(dim, v);
      auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(key, -1));
      for (; it != sorted.end() && it->first == key; ++it)
        if (result[static_cast<std::size_t>(it->second)] < 0)
          result[static_cast<std::size_t>(it->second)] = cell;
    }
  }
  return result;
}

}  // namespace coapt::mesh
