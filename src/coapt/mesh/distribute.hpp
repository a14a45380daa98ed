#pragma once
/// @file distribute.hpp
/// Distribution of a whole mesh over the ranks: partition the cells (METIS, dual graph
/// through shared facets), number the vertices so each rank owns a contiguous range of the
/// global numbering (matching PETSc layouts), and give each rank its cells, a ghost layer
/// (every cell sharing a vertex with one of its cells) and the boundary facets of those.

#include <mpi.h>

#include <vector>

#include "coapt/mesh/mesh.hpp"

namespace coapt::mesh {

/// How cells are assigned to ranks.
enum class Partitioner {
  metis,   ///< METIS_PartMeshDual (balanced, small interfaces); deterministic (fixed seed)
  blocks,  ///< contiguous blocks of the source's cell order (for tests of other layouts)
};

/// Distributes `whole` (meaningful on rank 0 of `comm` only; other ranks may pass an empty
/// Mesh) over `comm` and returns this rank's part. Collective on `comm`.
Mesh distribute(const Mesh& whole, MPI_Comm comm, Partitioner partitioner = Partitioner::metis);

/// Cell partition of `whole` into `n_parts` parts (one entry per cell). Serial.
std::vector<int> partition_cells(const Mesh& whole, int n_parts, Partitioner partitioner);

}  // namespace coapt::mesh
