#pragma once
/// @file gmsh_reader.hpp
/// Reading Gmsh meshes (.msh versions 2 and 4, ASCII and binary) through the Gmsh C++ API,
/// and the guard every use of that API in coapt goes through.
///
/// Gmsh keeps process-wide global state (one current model, options, a logger); every use
/// of it must hold a GmshSession, which serialises the users, initialises Gmsh once per
/// process (finalised at exit), silences it and turns its failures into InputErrors.

#include <mutex>
#include <string>

#include "coapt/mesh/mesh.hpp"

namespace coapt::mesh {

/// Scoped, exclusive use of Gmsh. On construction: takes a process-wide lock, initialises
/// Gmsh on first use (gmsh::finalize is registered with std::atexit), resets the options
/// coapt relies on (no terminal output, General.AbortOnError = 0 so that Gmsh reports
/// errors through its logger instead of throwing, one thread, Mesh.RandomSeed = 1, linear
/// elements, default mesh sizes and algorithms, ...), clears the model and starts the
/// Gmsh logger. On destruction: clears the model and stops the logger.
///
/// Sessions do not nest: constructing one while this thread holds one throws
/// InternalError (the inner one would clear the outer one's model).
/// Note that initialising Gmsh has process-wide side effects: it raises the stack size
/// limit, and General.NumThreads = 1 calls omp_set_num_threads(1).
class GmshSession {
 public:
  /// `source` names the file or generator in error messages ("<source>: <message>").
  explicit GmshSession(std::string source);
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
  ~GmshSession();

  const std::string& source() const { return source_; }

  /// Throws InputError "<source>: <messages>" if Gmsh logged an error (or fatal error) since
  /// the session began or the last check; passes Gmsh's warnings to coapt's debug log.
  void check_log();

  /// Calls `f()` (Gmsh API calls), turns anything it throws (Gmsh throws std::string and
  /// other non-std types) into InputError "<source>: <message>" (coapt::Error passes through
  /// unchanged), then calls check_log().
  template <class F>
  void run(F&& f) {
    try {
      f();
    } catch (...) {
      rethrow_as_input_error();
    }
    check_log();
  }

 private:
  [[noreturn]] void rethrow_as_input_error();
  std::string source_;
  std::unique_lock<std::mutex> lock_;
  std::size_t log_seen_ = 0;  ///< number of logger messages already checked
};

/// Reads a Gmsh mesh file into a whole (serial, MPI_COMM_SELF, all owned) Mesh.
///
///  - Cells are the elements of the highest dimension present: tetrahedra (type 4) if the
///    file has any 3D elements, else triangles (type 2), which must lie in the plane z = 0
///    (only x, y are kept). Any other element type of that dimension (quadrangles, prisms,
///    second-order elements, ...) is an InputError naming the type.
///  - cell_tags: the physical group (of the mesh's dimension) of each cell's entity, 0 if it
///    has none; an entity in two such groups is an InputError.
///  - Boundary facets: the elements of every physical group of dimension dim − 1 (lines in
///    2D, triangles in 3D), one facet per (element, group) — an element in two groups gives
///    two facets, a repeated element in one group one — oriented outward from their cell
///    (see topology.hpp); facet_cell is the cell having the facet as a face (the lower-numbered
///    one for an interior facet). A tagged facet that is no cell's face is an InputError
///    naming the element. Physical groups of lower dimension are ignored.
///  - groups: every physical group of dimension dim and dim − 1, cell groups first, each in
///    order of tag; unnamed ones are called "group_<tag>".
///  - Vertices: the nodes used by the cells, numbered 0..n−1 in increasing node tag;
///    original_vertex / original_cell are the file's node / element tags; cells are in order
///    of element tag.
///  - A consistently flipped mesh (every cell negative) is re-oriented (orient_cells); a
///    partly inverted one is returned as it is: run check_quality / require_valid.
/// Every failure (missing or unreadable file, truncated or malformed file, unsupported
/// elements, no cells) is an InputError whose message starts with "<path>: ".
Mesh read_gmsh(const std::string& path);

/// Converts the mesh of Gmsh's current model, as described for read_gmsh, with `source` as
/// the mesh's source and error prefix. Call inside a GmshSession (shared by read_gmsh and the
/// Gmsh-based generators).
Mesh mesh_from_gmsh_model(const std::string& source);

}  // namespace coapt::mesh
