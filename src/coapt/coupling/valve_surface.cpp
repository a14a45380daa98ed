#include "coapt/coupling/valve_surface.hpp"

#include <fmt/format.h>
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "coapt/core/error.hpp"
#include "coapt/transfer/geometry.hpp"
#include "coapt/transfer/search.hpp"

namespace coapt::coupling {

namespace {

template <int dim>
void mark_points_in_mesh(const mesh::Mesh& mesh, std::span<const double> points,
                         std::vector<int>& inside) {
  constexpr double tolerance = 1e-9;  // barycentric: relative to the cell's size
  // the owned cells' boxes, widened by the tolerance, in a uniform grid: each point visits
  // only the cells whose box holds it (linear in cells and points, in 2D and 3D alike)
  std::vector<transfer::Simplex<dim>> simplices;
  std::vector<transfer::Box<dim>> boxes;
  simplices.reserve(static_cast<std::size_t>(mesh.n_owned_cells));
  boxes.reserve(static_cast<std::size_t>(mesh.n_owned_cells));
  for (int c = 0; c < mesh.n_owned_cells; ++c) {
    std::array<transfer::Point<dim>, dim + 1> vertices;
    const auto cell = mesh.cell(c);
    for (int a = 0; a <= dim; ++a)
      for (int i = 0; i < dim; ++i) vertices[a][i] = mesh.point(cell[a])[i];
    simplices.push_back(transfer::make_simplex<dim>(vertices));
    const auto& simplex = simplices.back();
    double extent = 0;
    for (int i = 0; i < dim; ++i)
      extent = std::max(extent, simplex.box_upper[i] - simplex.box_lower[i]);
    boxes.push_back(simplex.degenerate()
                        ? transfer::Box<dim>::empty()
                        : transfer::Box<dim>::of(simplex).inflated(tolerance * extent + 1e-300));
  }
  transfer::BoxGrid<dim> grid;
  grid.build(boxes);
  for (std::size_t p = 0; p < inside.size(); ++p) {
    transfer::Point<dim> point;
    for (int i = 0; i < dim; ++i) point[i] = points[p * dim + static_cast<std::size_t>(i)];
    const transfer::Box<dim> at{point, point};
    grid.query(at, [&](int c) {
      if (inside[p]) return;
      const auto& simplex = simplices[static_cast<std::size_t>(c)];
      bool in = true;
      for (int a = 0; a <= dim && in; ++a) in = simplex.barycentric(a, point) >= -tolerance;
      if (in) inside[p] = 1;
    });
  }
}

}  // namespace

std::vector<char> points_in_mesh(const mesh::Mesh& mesh, std::span<const double> points) {
  std::vector<int> inside(points.size() / static_cast<std::size_t>(mesh.dim), 0);
  if (mesh.dim == 2)
    mark_points_in_mesh<2>(mesh, points, inside);
  else
    mark_points_in_mesh<3>(mesh, points, inside);
  MPI_Allreduce(MPI_IN_PLACE, inside.data(), static_cast<int>(inside.size()), MPI_INT, MPI_MAX,
                mesh.comm);
  return {inside.begin(), inside.end()};
}

std::vector<char> reached_nodes(const contact::Surface& surface, std::span<const char> seed,
                                std::span<const char> blocked) {
  const int n_nodes = surface.n_nodes();
  // the facets of each node
  std::vector<std::vector<int>> facets_of(static_cast<std::size_t>(n_nodes));
  for (int f = 0; f < surface.n_facets(); ++f)
    for (const int node : surface.facet(f)) facets_of[static_cast<std::size_t>(node)].push_back(f);
  std::vector<char> reached(static_cast<std::size_t>(n_nodes), 0);
  std::vector<int> front;
  for (int node = 0; node < n_nodes; ++node)
    if (seed[static_cast<std::size_t>(node)] && !blocked[static_cast<std::size_t>(node)]) {
      reached[static_cast<std::size_t>(node)] = 1;
      front.push_back(node);
    }
  while (!front.empty()) {
    const int node = front.back();
    front.pop_back();
    for (const int f : facets_of[static_cast<std::size_t>(node)])
      for (const int next : surface.facet(f)) {
        const auto k = static_cast<std::size_t>(next);
        if (reached[k] || blocked[k]) continue;
        reached[k] = 1;
        front.push_back(next);
      }
  }
  return reached;
}

std::vector<PetscInt> contact_zone_vertices(const std::vector<contact::PairState>& pairs) {
  std::vector<PetscInt> zone;
  for (const auto& pair : pairs) {
    if (pair.active.empty()) continue;
    for (int j = 0; j < pair.slave.n_nodes(); ++j)
      if (pair.active[static_cast<std::size_t>(j)])
        zone.push_back(pair.slave.global_vertex[static_cast<std::size_t>(j)]);
    const auto& master = pair.master;
    if (pair.master_x.size() != static_cast<std::size_t>(master.n_nodes() * master.dim)) continue;
    // ∫_Γm N_l at the current coordinates
    const auto support = contact::nodal_measures(master, pair.master_x);
    std::vector<double> covered(support.size(), 0.0);
    for (const auto& entry : pair.mortar.master_coupling)
      if (pair.active[static_cast<std::size_t>(entry.row)])
        covered[static_cast<std::size_t>(entry.column)] += entry.value;
    for (std::size_t l = 0; l < support.size(); ++l)
      if (support[l] > 0 && covered[l] >= 0.5 * support[l]) zone.push_back(master.global_vertex[l]);
  }
  std::sort(zone.begin(), zone.end());
  zone.erase(std::unique(zone.begin(), zone.end()), zone.end());
  return zone;
}

UpstreamSurface::UpstreamSurface(const mesh::Mesh& mesh, std::span<const int> tags,
                                 const std::string& groups,
                                 std::span<const PetscInt> dirichlet_dofs,
                                 const mesh::Mesh& fluid_mesh, const std::string& key,
                                 const std::string& solid)
    : mesh_(mesh), surface_(contact::gather_surface(mesh, tags, groups)) {
  const int n_nodes = surface_.n_nodes();
  for (int node = 0; node < n_nodes; ++node)
    node_of_vertex_.emplace(surface_.global_vertex[static_cast<std::size_t>(node)], node);
  // a node is clamped when one of its components is prescribed (on the rank owning it)
  std::vector<int> clamped(static_cast<std::size_t>(n_nodes), 0);
  const PetscInt first = mesh.vertex_offset, end = mesh.vertex_offset + mesh.n_owned_vertices;
  for (int node = 0; node < n_nodes; ++node) {
    const PetscInt vertex = surface_.global_vertex[static_cast<std::size_t>(node)];
    if (vertex < first || vertex >= end) continue;
    for (int i = 0; i < mesh.dim; ++i)
      if (std::binary_search(dirichlet_dofs.begin(), dirichlet_dofs.end(), vertex * mesh.dim + i))
        clamped[static_cast<std::size_t>(node)] = 1;
  }
  MPI_Allreduce(MPI_IN_PLACE, clamped.data(), n_nodes, MPI_INT, MPI_MAX, mesh.comm);
  clamped_.assign(clamped.begin(), clamped.end());
  in_fluid_ = points_in_mesh(fluid_mesh, surface_.reference);
  const std::vector<char> none(static_cast<std::size_t>(n_nodes), 0);
  const auto reached = reached_nodes(surface_, clamped_, none);
  const auto loose = std::find(reached.begin(), reached.end(), 0);
  if (loose != reached.end()) {
    const auto node = static_cast<std::size_t>(loose - reached.begin());
    const double* x = surface_.reference.data() + node * static_cast<std::size_t>(mesh.dim);
    throw InputError(fmt::format(
        "{}: a part of [{}] of solid '{}' is not joined to a clamped node (a `dirichlet` "
        "boundary of the solid), e.g. the node at ({:g}, {:g}{}): the swept flow counts these "
        "surfaces from the clamped base to the contact zone",
        key, surface_.name, solid, x[0], x[1], mesh.dim == 3 ? fmt::format(", {:g}", x[2]) : ""));
  }
}

std::vector<char> UpstreamSurface::vertex_levels(
    const std::vector<contact::PairState>& pairs) const {
  const auto n_nodes = static_cast<std::size_t>(surface_.n_nodes());
  std::vector<char> blocked(n_nodes, 0);
  for (const PetscInt vertex : contact_zone_vertices(pairs)) {
    const auto found = node_of_vertex_.find(vertex);
    if (found != node_of_vertex_.end()) blocked[static_cast<std::size_t>(found->second)] = 1;
  }
  const auto reached = reached_nodes(surface_, clamped_, blocked);
  std::vector<char> levels(static_cast<std::size_t>(mesh_.n_vertices()), kPastContact);
  for (int v = 0; v < mesh_.n_vertices(); ++v) {
    const auto found = node_of_vertex_.find(mesh_.global_vertex[static_cast<std::size_t>(v)]);
    if (found == node_of_vertex_.end() || !reached[static_cast<std::size_t>(found->second)])
      continue;
    levels[static_cast<std::size_t>(v)] =
        in_fluid_[static_cast<std::size_t>(found->second)] ? kCounted : kOutsideFluid;
  }
  return levels;
}

}  // namespace coapt::coupling
