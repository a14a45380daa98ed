#pragma once
/// @file generators.hpp
/// Mesh generators: structured rectangles and boxes (built directly, fast) and unstructured
/// ones through Gmsh's OpenCASCADE kernel, plus meshing a .geo file.
///
/// Every generator returns a whole serial mesh (MPI_COMM_SELF, everything owned) with
///  - one cell group "domain" (tag 1),
///  - boundary facet groups "left" (x = x0), "right" (x = x1), then in 2D "bottom" (y = y0),
///    "top" (y = y1) with tags 1..4, in 3D "front" (y = y0), "back" (y = y1), "bottom"
///    (z = z0), "top" (z = z1) with tags 1..6; facets are listed group by group, each
///    outward-oriented (topology.hpp) with facet_cell set,
///  - positively oriented cells,
///  - original_vertex / original_cell = 1-based vertex / cell numbers,
/// and is deterministic (same arguments, same mesh). Bad arguments are InputErrors.

#include <string>

#include "coapt/mesh/mesh.hpp"

namespace coapt::mesh {

/// How structured_rectangle cuts each square (corners v00 = (x_i, y_j), v10, v01, v11).
enum class Diagonal {
  right,        ///< diagonal v00–v11 ("/"): triangles (v00, v10, v11), (v00, v11, v01)
  left,         ///< diagonal v10–v01 ("\"): triangles (v00, v10, v01), (v10, v11, v01)
  alternating,  ///< right where i + j is even, left where it is odd (checkerboard)
  crossed,      ///< both diagonals: a centre vertex and 4 triangles per square
};

/// "right", "left", "alternating" or "crossed" (InputError otherwise).
Diagonal parse_diagonal(const std::string& name);
const char* to_string(Diagonal diagonal);

/// [x0, x1] × [y0, y1] cut into nx × ny equal squares (rectangles), 2 triangles each (4 with
/// Diagonal::crossed). Vertices: grid vertex (i, j) is number j (nx + 1) + i (0-based), then
/// with `crossed` the centre of square (i, j) is (nx + 1)(ny + 1) + j nx + i. Cells: square by
/// square (j outer, i inner), in the order given for the pattern.
Mesh structured_rectangle(double x0, double y0, double x1, double y1, int nx, int ny,
                          Diagonal diagonal = Diagonal::right);

/// [x0, x1] × [y0, y1] × [z0, z1] cut into nx × ny × nz equal boxes, 6 tetrahedra each: the
/// Kuhn (Freudenthal) subdivision along the diagonal from (x_i, y_j, z_k) to
/// (x_i+1, y_j+1, z_k+1), the same in every box, so the mesh is conforming. Vertex (i, j, k)
/// is number (k (ny + 1) + j)(nx + 1) + i; cells box by box (k, j, i from outer to inner).
/// Linear time; the 64³ box (1.57 M tetrahedra) takes a fraction of a second.
Mesh structured_box(double x0, double y0, double z0, double x1, double y1, double z1, int nx,
                    int ny, int nz);

/// Unstructured triangle mesh of the rectangle, through Gmsh (OpenCASCADE rectangle,
/// Frontal-Delaunay, Mesh.MeshSizeMax = h, random seed 1, one thread). Same groups as
/// structured_rectangle. Deterministic for a given Gmsh version.
Mesh unstructured_rectangle(double x0, double y0, double x1, double y1, double h);

/// Unstructured tetrahedral mesh of the box, through Gmsh (OpenCASCADE box, Delaunay,
/// Mesh.MeshSizeMax = h, random seed 1, one thread). Same groups as structured_box.
Mesh unstructured_box(double x0, double y0, double z0, double x1, double y1, double z1, double h);

/// Meshes a Gmsh .geo file (in dimension 3 if it defines volumes, else 2) and converts it as
/// read_gmsh does (physical groups, tags, checks; original numbers are Gmsh's tags).
/// `h` is the largest element size (Gmsh's Mesh.MeshSizeMax, replacing any the file sets):
/// elements are at most about h everywhere, and smaller where the file asks for smaller
/// sizes (characteristic lengths at points, size fields); the file's other options apply,
/// except Mesh.MeshSizeMax and Mesh.MeshSizeFactor, which are set here after the file is read.
/// Mesh.ElementOrder must stay 1. A mesh the file already generated itself ("Mesh 2;") is
/// discarded and redone at size h. `size_factor` multiplies every size after the cap h
/// (Gmsh's Mesh.MeshSizeFactor, replacing any the file sets): refinement levels pass the
/// level-0 h and 2^-level, so every size, local refinement included, halves per level.
Mesh mesh_geo_file(const std::string& path, double h, double size_factor = 1.0);

}  // namespace coapt::mesh
