#pragma once
/// @file mesh.hpp
/// The P1 simplex mesh: triangles in 2D, tetrahedra in 3D, stored as flat arrays.
///
/// A Mesh is either the whole mesh on one rank (as read or generated, before
/// distribution: every entity "owned") or one rank's part of a distributed mesh:
///  - vertices: owned ones first [0, n_owned_vertices), then ghosts; owned vertices have
///    the contiguous global numbers [vertex_offset, vertex_offset + n_owned_vertices), so
///    a PETSc vector with n_owned_vertices local entries (per component) matches them;
///  - cells: owned ones first [0, n_owned_cells) (each cell is owned by exactly one rank:
///    assemble over these), then a ghost layer (every cell sharing a vertex with an owned
///    cell); owned cells have the contiguous global numbers of global_cell;
///  - boundary facets: those of local cells, each with the local cell it bounds.

#include <mpi.h>
#include <petscsys.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace coapt::mesh {

/// A named Gmsh physical group (or a generator's named region).
struct PhysicalGroup {
  std::string name;
  int dim = 0;  ///< 0 points, 1 curves, 2 surfaces, 3 volumes
  int tag =
      0;  ///< the tag stored in cell_tags (dim == mesh dim) or facet_tags (dim == mesh dim - 1)
};

/// The mesh data; see the file comment for the ordering contract.
struct Mesh {
  int dim = 0;                    ///< 2 or 3
  std::string source;             ///< file or generator it came from (for messages)
  MPI_Comm comm = MPI_COMM_SELF;  ///< communicator the mesh is distributed over

  // Vertices
  std::vector<double> coordinates;            ///< n_vertices × dim, row-major [m]
  std::vector<PetscInt> global_vertex;        ///< global (PETSc-layout) number of each local vertex
  std::vector<std::int64_t> original_vertex;  ///< number in the source file (Gmsh node tag)
  int n_owned_vertices = 0;
  PetscInt vertex_offset = 0;  ///< global number of the first owned vertex
  PetscInt n_global_vertices = 0;

  // Cells
  std::vector<int> cells;                   ///< n_cells × (dim + 1) local vertex indices
  std::vector<int> cell_tags;               ///< physical tag of each cell (0 if none)
  std::vector<std::int64_t> original_cell;  ///< element number in the source (Gmsh element tag)
  int n_owned_cells = 0;
  std::int64_t n_global_cells = 0;
  /// Global number of each local cell (owned cells numbered rank by rank, in their local
  /// order, so that a PETSc vector with n_owned_cells local entries matches them); empty on a
  /// whole mesh, whose cells are numbered by their index.
  std::vector<PetscInt> global_cell;

  // Boundary facets (segments in 2D, triangles in 3D)
  std::vector<int> facets;      ///< n_facets × dim local vertex indices (normal out of facet_cell)
  std::vector<int> facet_tags;  ///< physical tag of each facet
  std::vector<int> facet_cell;  ///< local cell each facet bounds

  std::vector<PhysicalGroup> groups;  ///< named groups, cells' and facets' tags

  int vertices_per_cell() const { return dim + 1; }
  int n_vertices() const { return static_cast<int>(global_vertex.size()); }
  int n_cells() const { return dim == 0 ? 0 : static_cast<int>(cells.size()) / (dim + 1); }
  int n_facets() const { return dim == 0 ? 0 : static_cast<int>(facets.size()) / dim; }
  /// Local vertex indices of cell c (dim + 1 entries).
  std::span<const int> cell(int c) const {
    return {cells.data() + static_cast<std::size_t>(c) * (dim + 1),
            static_cast<std::size_t>(dim + 1)};
  }
  /// Coordinates of local vertex v (dim entries).
  std::span<const double> point(int v) const {
    return {coordinates.data() + static_cast<std::size_t>(v) * dim, static_cast<std::size_t>(dim)};
  }
  /// The group with this name, or nullptr.
  const PhysicalGroup* find_group(const std::string& name) const;
  /// The group with this name; throws InputError naming the mesh and the groups it has.
  const PhysicalGroup& group(const std::string& name) const;
};

/// Signed measure of a simplex: area (2D, counter-clockwise positive) or volume (3D,
/// positive for right-handed vertex order), from `dim + 1` points of `dim` coordinates.
double signed_measure(int dim, const double* const* points);
/// Signed measure of local cell c of `mesh`.
double cell_signed_measure(const Mesh& mesh, int c);

}  // namespace coapt::mesh
