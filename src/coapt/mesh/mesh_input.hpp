#pragma once
/// @file mesh_input.hpp
/// The `mesh` section of a case: where a mesh comes from (a Gmsh file, a .geo file meshed
/// at a size, or a built-in generator), its refinement level, and how it is distributed.

#include <mpi.h>

#include <array>
#include <string>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/mesh.hpp"
#include "coapt/mesh/quality.hpp"

namespace coapt::mesh {

/// The parameters of a `mesh` section, read once.
struct MeshInput {
  std::string type;           ///< rectangle | box | gmsh | geo
  std::string file;           ///< .msh or .geo (gmsh, geo), resolved against the case folder
  std::vector<double> lower;  ///< generator box corner [m]
  std::vector<double> upper;  ///< generator box corner [m]
  std::vector<int> cells;     ///< cells per direction at level 0 (structured)
  bool structured = true;     ///< structured (generators) or Gmsh's unstructured mesher
  double size = 0;            ///< element size at level 0 (unstructured, geo) [m]
  int level = 0;              ///< refinement level: each level halves the size
  Partitioner partitioner = Partitioner::metis;

  /// Reads and checks the section. `dim` is 2 or 3 for generators (0: any).
  static MeshInput read(const config::Section& section, const std::string& case_directory);
  /// A one-line description ("box [0,1]^3, 24x24x24 cells, structured").
  std::string describe() const;
};

/// Adds `levels` refinement levels to a mesh input (geo sizes and generator cell counts halve
/// per level); InputError naming `where` for a mesh read from a .msh file, which cannot be
/// refined.
void add_refinement_levels(MeshInput& input, int levels, const std::string& where);

/// Loads (on rank 0), checks quality (inverted or degenerate cells are an InputError naming
/// them) and distributes the mesh over `comm`. Collective. `report` receives the quality
/// report of the whole mesh (on every rank).
Mesh load_mesh(const MeshInput& input, MPI_Comm comm, QualityReport* report = nullptr);

}  // namespace coapt::mesh
