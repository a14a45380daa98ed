#pragma once
/// @file vtk_writer.hpp
/// Time series of a distributed P1 simplex mesh and its fields in VTK's XML formats, as
/// ParaView opens them.
///
/// Files of a series with base name BASE in directory DIR (step s = 0, 1, 2, ... counts the
/// calls to write(), printed with 6 digits; rank r with at least 4 digits):
///   DIR/BASE.pvd                               the collection: every step with its time
///                                              (rewritten by rank 0 after each step);
///   DIR/BASE_000042.pvtu                       step 42: names the pieces (rank 0);
///   DIR/BASE_pieces/BASE_000042_r0001.vtu      step 42, the piece of rank 1.
/// Open BASE.pvd in ParaView for the time series. A piece holds the rank's owned cells and
/// the vertices they use (including ghost vertices, so vertices at partition boundaries
/// appear in several pieces), renumbered compactly in local-vertex order. Each piece also
/// carries the cell data "rank" (Int32, the writing rank) and the point data "global_id"
/// (Int64, Mesh::global_vertex) for inspection.
///
/// Encoding: format="binary" (base64, a UInt64 byte-count header before each array's
/// data, header_type="UInt64"), byte order of the machine (LittleEndian on x86 and ARM);
/// points and fields Float64, connectivity and offsets Int64, cell types UInt8 (VTK_TRIANGLE
/// 5 in 2D, VTK_TETRA 10 in 3D); 2D coordinates are padded with z = 0.

#include <mpi.h>

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "coapt/mesh/mesh.hpp"

namespace coapt::io {

/// One array to write with the mesh.
struct Field {
  enum class Location { vertex, cell };

  std::string name;  ///< unique within one write; not "rank" or "global_id" (those are ours)
  int n_components = 1;
  Location location = Location::vertex;
  /// Row-major, n_components values per entry:
  ///  - vertex fields: one entry per local vertex, n_vertices() entries (owned and ghosts).
  ///    Every vertex used by an owned cell is written, so ghost entries must be current
  ///    (ghost-updated) for those;
  ///  - cell fields: n_owned_cells entries, or n_cells() entries (ghost cells' entries are
  ///    then ignored).
  /// In 2D, a field with 2 components is written with 3 (third = 0) so that ParaView treats
  /// it as a vector (glyphs, Warp By Vector); every other count is written as given.
  std::span<const double> values;
};

/// A time series of VTK files; see the file comment for the layout. Not thread-safe.
class VtkSeries {
 public:
  /// Collective on `comm` (which must outlive the series and be the communicator of the
  /// meshes written): rank 0 creates `directory` (and parents) if missing. Throws
  /// coapt::Error on every rank if it cannot, or if `base_name` is empty or contains '/'.
  VtkSeries(MPI_Comm comm, std::filesystem::path directory, std::string base_name);

  /// Writes one step: every rank its piece, rank 0 the .pvtu, then rank 0 rewrites the
  /// .pvd with every step so far. Collective on the series' communicator; when it returns,
  /// all files of the step are complete (so rank 0 may read them).
  ///
  /// Every decision to throw is collective, so all ranks throw the same coapt::Error and
  /// none hangs:
  ///  - a value that is not finite in a field (or a non-finite time): coapt::Error naming
  ///    the field, the first bad entry (local and global vertex / cell number, component,
  ///    rank) and the value; nothing of the step is written;
  ///  - a field of the wrong size, a duplicated or reserved name, a mesh that does not
  ///    fit (dimension, cell vertex indices): coapt::InternalError; nothing is written;
  ///  - a file that cannot be written: coapt::Error naming it.
  void write(const mesh::Mesh& mesh, double time, std::span<const Field> fields);

  /// Number of steps written so far (the number the next step gets).
  int n_steps() const { return static_cast<int>(steps_.size()); }
  /// Path of the .pvd collection.
  std::filesystem::path pvd_path() const;
  /// Path of the .pvtu of `step`.
  std::filesystem::path pvtu_path(int step) const;
  /// Path of the piece of `rank` in `step`.
  std::filesystem::path piece_path(int step, int rank) const;

 private:
  struct Step {
    double time;
    std::string pvtu_file;  ///< relative to directory_
  };

  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
  std::filesystem::path directory_;
  std::string base_name_;
  std::vector<Step> steps_;
};

namespace detail {
/// Base64 (RFC 4648, with padding) of `bytes`. Exposed for tests.
std::string base64_encode(std::span<const std::byte> bytes);
}  // namespace detail

}  // namespace coapt::io
