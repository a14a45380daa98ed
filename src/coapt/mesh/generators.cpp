#include "coapt/mesh/generators.hpp"

#include <fmt/format.h>
#include <gmsh.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <span>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/mesh/gmsh_reader.hpp"
#include "coapt/mesh/topology.hpp"

namespace coapt::mesh {
namespace {

// The (n+1) coordinates of an equal subdivision of [a, b], with exact end points.
std::vector<double> subdivide(double a, double b, int n) {
  std::vector<double> x(static_cast<std::size_t>(n) + 1);
  for (int i = 0; i <= n; ++i) x[i] = a + (b - a) * i / n;
  x[n] = b;
  return x;
}

void check_interval(const std::string& source, const char* axis, double a, double b) {
  if (!(std::isfinite(a) && std::isfinite(b) && a < b))
    throw InputError(
        fmt::format("{}: the {} range [{:g}, {:g}] is empty or not finite", source, axis, a, b));
}

void check_divisions(const std::string& source, const char* name, int n) {
  if (n < 1) throw InputError(fmt::format("{}: {} must be at least 1 (got {})", source, name, n));
}

void check_size(const std::string& source, std::int64_t n_cells, int per_cell) {
  if (n_cells > INT_MAX / per_cell)
    throw InputError(
        fmt::format("{}: {} cells is more than coapt's 32-bit indices can hold", source, n_cells));
}

// Fills the serial bookkeeping: all owned, global = local, 1-based original numbers.
void finish_serial(Mesh& mesh) {
  const int n_vertices = static_cast<int>(mesh.coordinates.size()) / mesh.dim;
  mesh.comm = MPI_COMM_SELF;
  mesh.global_vertex.resize(n_vertices);
  std::iota(mesh.global_vertex.begin(), mesh.global_vertex.end(), PetscInt{0});
  mesh.original_vertex.resize(n_vertices);
  std::iota(mesh.original_vertex.begin(), mesh.original_vertex.end(), std::int64_t{1});
  mesh.n_owned_vertices = n_vertices;
  mesh.vertex_offset = 0;
  mesh.n_global_vertices = n_vertices;
  const int n_cells = mesh.n_cells();
  mesh.original_cell.resize(n_cells);
  std::iota(mesh.original_cell.begin(), mesh.original_cell.end(), std::int64_t{1});
  if (mesh.cell_tags.size() != static_cast<std::size_t>(n_cells)) mesh.cell_tags.assign(n_cells, 1);
  mesh.n_owned_cells = n_cells;
  mesh.n_global_cells = n_cells;
}

const char* const kSides2[] = {"left", "right", "bottom", "top"};
const char* const kSides3[] = {"left", "right", "front", "back", "bottom", "top"};

void add_groups(Mesh& mesh) {
  mesh.groups.push_back({"domain", mesh.dim, 1});
  int tag = 1;
  if (mesh.dim == 2)
    for (const char* side : kSides2) mesh.groups.push_back({side, 1, tag++});
  else
    for (const char* side : kSides3) mesh.groups.push_back({side, 2, tag++});
}

// ---- Kuhn subdivision of the unit cube ----------------------------------------------------

// Cube corner c (0..7) is at (c & 1, (c >> 1) & 1, (c >> 2) & 1).
struct Kuhn {
  std::array<std::array<int, 4>, 6> tets{};  // corners of each tetrahedron, positive
  // For each side (left, right, front, back, bottom, top): the (tet, local facet) pairs
  // whose facet lies on that side of the cube (two per side).
  std::array<std::vector<std::pair<int, int>>, 6> side_facets;

  Kuhn() {
    const int permutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                    {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int t = 0; t < 6; ++t) {
      const int* p = permutations[t];
      const int c1 = 1 << p[0];
      const int c2 = c1 | (1 << p[1]);
      tets[t] = {0, c1, c2, 7};
      double corner[4][3];
      const double* points[4];
      for (int k = 0; k < 4; ++k) {
        for (int d = 0; d < 3; ++d) corner[k][d] = (tets[t][k] >> d) & 1;
        points[k] = corner[k];
      }
      if (signed_measure(3, points) < 0) std::swap(tets[t][2], tets[t][3]);
    }
    for (int side = 0; side < 6; ++side) {
      const int axis = side / 2, bit = side % 2;
      for (int t = 0; t < 6; ++t)
        for (int f = 0; f < 4; ++f) {
          bool on_side = true;
          for (int k = 0; k < 3; ++k)
            on_side = on_side && ((tets[t][local_facet_vertex(3, f, k)] >> axis) & 1) == bit;
          if (on_side) side_facets[side].emplace_back(t, f);
        }
    }
  }
};

const Kuhn& kuhn() {
  static const Kuhn instance;
  return instance;
}

// ---- Gmsh-based generation -----------------------------------------------------------------

// Finds the boundary entity of dimension `dim` of the box [lo, hi] lying on the plane
// coordinate `axis` = lo[axis] (high = false) or hi[axis], by bounding boxes.
int find_side(const std::string& source, int dim, int axis, bool high, const double* lo,
              const double* hi, int n_axes) {
  double min_extent = INFINITY;
  for (int d = 0; d < n_axes; ++d) min_extent = std::min(min_extent, hi[d] - lo[d]);
  const double tolerance = 0.25 * min_extent;  // robust against OCC's enlarged boxes
  const double target = high ? hi[axis] : lo[axis];
  gmsh::vectorpair entities;
  gmsh::model::getEntities(entities, dim);
  int found = -1, count = 0;
  for (const auto& [d, tag] : entities) {
    double b[6];
    gmsh::model::getBoundingBox(d, tag, b[0], b[1], b[2], b[3], b[4], b[5]);
    if (std::abs(b[axis] - target) < tolerance && std::abs(b[3 + axis] - target) < tolerance) {
      found = tag;
      ++count;
    }
  }
  if (count != 1)
    throw InternalError(fmt::format("{}: found {} boundary entities on side {}{} instead of 1",
                                    source, count, high ? "+" : "-", "xyz"[axis]));
  return found;
}

Mesh generate_with_gmsh(GmshSession& session, int dim, const double* lo, const double* hi,
                        double h) {
  const std::string& source = session.source();
  Mesh mesh;
  session.run([&] {
    int volume = 0;
    if (dim == 2)
      volume = gmsh::model::occ::addRectangle(lo[0], lo[1], 0, hi[0] - lo[0], hi[1] - lo[1]);
    else
      volume = gmsh::model::occ::addBox(lo[0], lo[1], lo[2], hi[0] - lo[0], hi[1] - lo[1],
                                        hi[2] - lo[2]);
    gmsh::model::occ::synchronize();
    gmsh::model::addPhysicalGroup(dim, {volume}, 1);
    gmsh::model::setPhysicalName(dim, 1, "domain");
    const auto& sides =
        dim == 2 ? std::span<const char* const>(kSides2) : std::span<const char* const>(kSides3);
    for (int side = 0; side < static_cast<int>(sides.size()); ++side) {
      const int entity = find_side(source, dim - 1, side / 2, side % 2 == 1, lo, hi, dim);
      gmsh::model::addPhysicalGroup(dim - 1, {entity}, side + 1);
      gmsh::model::setPhysicalName(dim - 1, side + 1, sides[side]);
    }
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    gmsh::model::mesh::generate(dim);
  });
  session.run([&] { mesh = mesh_from_gmsh_model(source); });
  // Generators number from 1 (the Gmsh tags are an artefact of the meshing).
  std::iota(mesh.original_vertex.begin(), mesh.original_vertex.end(), std::int64_t{1});
  std::iota(mesh.original_cell.begin(), mesh.original_cell.end(), std::int64_t{1});
  return mesh;
}

void check_mesh_size(const std::string& source, int dim, const double* lo, const double* hi,
                     double h) {
  if (!(std::isfinite(h) && h > 0))
    throw InputError(fmt::format("{}: the mesh size h must be positive (got {:g})", source, h));
  // Rough cell count: measure / measure of the regular simplex of edge h.
  double measure = 1;
  for (int d = 0; d < dim; ++d) measure *= hi[d] - lo[d];
  const double simplex = dim == 2 ? std::sqrt(3.0) / 4 * h * h : h * h * h / (6 * std::sqrt(2.0));
  const double estimate = measure / simplex;
  constexpr double kMaxCells = 2e8;
  if (estimate > kMaxCells)
    throw InputError(fmt::format("{}: h = {:g} would give about {:.3g} cells (more than {:g})",
                                 source, h, estimate, kMaxCells));
}

}  // namespace

Diagonal parse_diagonal(const std::string& name) {
  for (const Diagonal d :
       {Diagonal::right, Diagonal::left, Diagonal::alternating, Diagonal::crossed})
    if (name == to_string(d)) return d;
  throw InputError("unknown diagonal pattern '" + name +
                   "' (expected right, left, alternating or crossed)");
}

const char* to_string(Diagonal diagonal) {
  switch (diagonal) {
    case Diagonal::right:
      return "right";
    case Diagonal::left:
      return "left";
    case Diagonal::alternating:
      return "alternating";
    case Diagonal::crossed:
      return "crossed";
  }
  return "?";
}

Mesh structured_rectangle(double x0, double y0, double x1, double y1, int nx, int ny,
                          Diagonal diagonal) {
  Mesh mesh;
  mesh.dim = 2;
  mesh.source = fmt::format("structured_rectangle([{:g}, {:g}] x [{:g}, {:g}], {} x {}, {})", x0,
                            x1, y0, y1, nx, ny, to_string(diagonal));
  check_interval(mesh.source, "x", x0, x1);
  check_interval(mesh.source, "y", y0, y1);
  check_divisions(mesh.source, "nx", nx);
  check_divisions(mesh.source, "ny", ny);
  const bool crossed = diagonal == Diagonal::crossed;
  const int per_square = crossed ? 4 : 2;
  check_size(mesh.source, std::int64_t{nx} * ny * per_square, 3);

  const auto x = subdivide(x0, x1, nx), y = subdivide(y0, y1, ny);
  const int n_grid = (nx + 1) * (ny + 1);
  mesh.coordinates.reserve(2 * (static_cast<std::size_t>(n_grid) + (crossed ? nx * ny : 0)));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) mesh.coordinates.insert(mesh.coordinates.end(), {x[i], y[j]});
  if (crossed)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        mesh.coordinates.insert(mesh.coordinates.end(),
                                {0.5 * (x[i] + x[i + 1]), 0.5 * (y[j] + y[j + 1])});

  auto grid = [nx](int i, int j) { return j * (nx + 1) + i; };
  mesh.cells.reserve(static_cast<std::size_t>(nx) * ny * per_square * 3);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int v00 = grid(i, j), v10 = grid(i + 1, j), v01 = grid(i, j + 1),
                v11 = grid(i + 1, j + 1);
      const bool right =
          diagonal == Diagonal::right || (diagonal == Diagonal::alternating && (i + j) % 2 == 0);
      if (crossed) {
        const int c = n_grid + j * nx + i;
        mesh.cells.insert(mesh.cells.end(), {v00, v10, c, v10, v11, c, v11, v01, c, v01, v00, c});
      } else if (right) {
        mesh.cells.insert(mesh.cells.end(), {v00, v10, v11, v00, v11, v01});
      } else {
        mesh.cells.insert(mesh.cells.end(), {v00, v10, v01, v10, v11, v01});
      }
    }
  finish_serial(mesh);
  add_groups(mesh);

  // Boundary edges side by side, each with the cell of its square that has it.
  auto add_edge = [&](int a, int b, int square, int tag) {
    int cell = -1;
    for (int c = square * per_square; c < (square + 1) * per_square && cell < 0; ++c) {
      const auto v = mesh.cell(c);
      if (std::find(v.begin(), v.end(), a) != v.end() &&
          std::find(v.begin(), v.end(), b) != v.end())
        cell = c;
    }
    mesh.facets.insert(mesh.facets.end(), {a, b});
    orient_facet_outward(mesh, cell, std::span<int>(mesh.facets.end() - 2, mesh.facets.end()));
    mesh.facet_tags.push_back(tag);
    mesh.facet_cell.push_back(cell);
  };
  for (int j = 0; j < ny; ++j) add_edge(grid(0, j), grid(0, j + 1), j * nx, 1);
  for (int j = 0; j < ny; ++j) add_edge(grid(nx, j), grid(nx, j + 1), j * nx + nx - 1, 2);
  for (int i = 0; i < nx; ++i) add_edge(grid(i, 0), grid(i + 1, 0), i, 3);
  for (int i = 0; i < nx; ++i) add_edge(grid(i, ny), grid(i + 1, ny), (ny - 1) * nx + i, 4);
  return mesh;
}

Mesh structured_box(double x0, double y0, double z0, double x1, double y1, double z1, int nx,
                    int ny, int nz) {
  Mesh mesh;
  mesh.dim = 3;
  mesh.source =
      fmt::format("structured_box([{:g}, {:g}] x [{:g}, {:g}] x [{:g}, {:g}], {} x {} x {})", x0,
                  x1, y0, y1, z0, z1, nx, ny, nz);
  check_interval(mesh.source, "x", x0, x1);
  check_interval(mesh.source, "y", y0, y1);
  check_interval(mesh.source, "z", z0, z1);
  check_divisions(mesh.source, "nx", nx);
  check_divisions(mesh.source, "ny", ny);
  check_divisions(mesh.source, "nz", nz);
  check_size(mesh.source, std::int64_t{nx} * ny * nz * 6, 4);

  const auto x = subdivide(x0, x1, nx), y = subdivide(y0, y1, ny), z = subdivide(z0, z1, nz);
  const std::size_t n_vertices = static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1);
  mesh.coordinates.resize(3 * n_vertices);
  {
    double* p = mesh.coordinates.data();
    for (int k = 0; k <= nz; ++k)
      for (int j = 0; j <= ny; ++j)
        for (int i = 0; i <= nx; ++i) {
          *p++ = x[i];
          *p++ = y[j];
          *p++ = z[k];
        }
  }
  // Vertex number of corner c of box (i, j, k) = base + offset[c].
  const int sx = 1, sy = nx + 1, sz = (nx + 1) * (ny + 1);
  int offset[8];
  for (int c = 0; c < 8; ++c) offset[c] = (c & 1) * sx + ((c >> 1) & 1) * sy + ((c >> 2) & 1) * sz;
  const Kuhn& table = kuhn();

  const std::size_t n_boxes = static_cast<std::size_t>(nx) * ny * nz;
  mesh.cells.resize(n_boxes * 24);
  {
    int* cell = mesh.cells.data();
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const int base = k * sz + j * sy + i;
          for (const auto& tet : table.tets)
            for (const int corner : tet) *cell++ = base + offset[corner];
        }
  }
  finish_serial(mesh);
  add_groups(mesh);

  // Boundary triangles side by side: two per box face, with the tetrahedra that own them.
  const int n[3] = {nx, ny, nz};
  for (int side = 0; side < 6; ++side) {
    const int axis = side / 2;
    const int fixed = side % 2 == 0 ? 0 : n[axis] - 1;  // box index along the axis
    // Loop over the boxes of that layer in (k, j, i) order.
    const int lo2 = axis == 2 ? fixed : 0, hi2 = axis == 2 ? fixed + 1 : nz;
    const int lo1 = axis == 1 ? fixed : 0, hi1 = axis == 1 ? fixed + 1 : ny;
    const int lo0 = axis == 0 ? fixed : 0, hi0 = axis == 0 ? fixed + 1 : nx;
    for (int k = lo2; k < hi2; ++k)
      for (int j = lo1; j < hi1; ++j)
        for (int i = lo0; i < hi0; ++i) {
          const int box = (k * ny + j) * nx + i;
          const int base = k * sz + j * sy + i;
          for (const auto& [t, f] : table.side_facets[side]) {
            for (int q = 0; q < 3; ++q)
              mesh.facets.push_back(base + offset[table.tets[t][local_facet_vertex(3, f, q)]]);
            mesh.facet_tags.push_back(side + 1);
            mesh.facet_cell.push_back(box * 6 + t);
          }
        }
  }
  return mesh;
}

Mesh unstructured_rectangle(double x0, double y0, double x1, double y1, double h) {
  const std::string source = fmt::format(
      "unstructured_rectangle([{:g}, {:g}] x [{:g}, {:g}], h = {:g})", x0, x1, y0, y1, h);
  check_interval(source, "x", x0, x1);
  check_interval(source, "y", y0, y1);
  const double lo[3] = {x0, y0, 0}, hi[3] = {x1, y1, 0};
  check_mesh_size(source, 2, lo, hi, h);
  GmshSession session(source);
  return generate_with_gmsh(session, 2, lo, hi, h);
}

Mesh unstructured_box(double x0, double y0, double z0, double x1, double y1, double z1, double h) {
  const std::string source =
      fmt::format("unstructured_box([{:g}, {:g}] x [{:g}, {:g}] x [{:g}, {:g}], h = {:g})", x0, x1,
                  y0, y1, z0, z1, h);
  check_interval(source, "x", x0, x1);
  check_interval(source, "y", y0, y1);
  check_interval(source, "z", z0, z1);
  const double lo[3] = {x0, y0, z0}, hi[3] = {x1, y1, z1};
  check_mesh_size(source, 3, lo, hi, h);
  GmshSession session(source);
  return generate_with_gmsh(session, 3, lo, hi, h);
}

Mesh mesh_geo_file(const std::string& path, double h, double size_factor) {
  namespace fs = std::filesystem;
  std::error_code error;
  const auto status = fs::status(path, error);
  if (!fs::exists(status)) throw InputError(path + ": cannot open the .geo file: no such file");
  if (fs::is_directory(status))
    throw InputError(path + ": cannot open the .geo file: it is a directory");
  if (!std::ifstream(path)) throw InputError(path + ": cannot open the .geo file");
  if (!(std::isfinite(h) && h > 0))
    throw InputError(fmt::format("{}: the mesh size h must be positive (got {:g})", path, h));

  GmshSession session(path);
  Mesh mesh;
  session.run([&] { gmsh::merge(path); });
  session.run([&] {
    std::vector<int> types;
    gmsh::model::mesh::getElementTypes(types);
    if (!types.empty()) gmsh::model::mesh::clear();  // the file meshed itself: redo it
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    gmsh::option::setNumber("Mesh.MeshSizeFactor", size_factor);
    const int dim = gmsh::model::getDimension();
    if (dim < 2) throw InputError(path + ": the geometry has no surfaces or volumes to mesh");
    double lo[3], hi[3];
    gmsh::model::getBoundingBox(-1, -1, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    check_mesh_size(path, dim, lo, hi, h);
    gmsh::model::mesh::generate(dim);
  });
  session.run([&] { mesh = mesh_from_gmsh_model(path); });
  return mesh;
}

}  // namespace coapt::mesh
