#include "coapt/mesh/gmsh_reader.hpp"

#include <fmt/format.h>
#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <set>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/mesh/quality.hpp"
#include "coapt/mesh/topology.hpp"

namespace coapt::mesh {
namespace {

// ---- Gmsh session state -------------------------------------------------------------------

std::mutex& gmsh_mutex() {
  static std::mutex mutex;
  return mutex;
}

thread_local bool this_thread_in_session = false;

void finalize_gmsh_at_exit() {
  try {
    gmsh::finalize();
  } catch (...) {
  }
}

void initialize_gmsh_once() {
  static bool initialized = false;  // guarded by gmsh_mutex()
  if (initialized) return;
  try {
    // No command-line arguments, no configuration files from the user's home directory.
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
  } catch (...) {
    throw Error("could not initialise Gmsh");
  }
  initialized = true;
  std::atexit(finalize_gmsh_at_exit);
}

// Options reset at the start of every session: a .geo file (or a test) may have changed any
// of them, and Gmsh options are global.
void reset_options() {
  static const std::pair<const char*, double> options[] = {
      {"General.Terminal", 0},
      {"General.AbortOnError", 0},
      {"General.Verbosity", 2},  // errors and warnings reach the logger; no info chatter
      {"General.NumThreads", 1},
      {"Mesh.MaxNumThreads1D", 1},
      {"Mesh.MaxNumThreads2D", 1},
      {"Mesh.MaxNumThreads3D", 1},
      {"Mesh.RandomSeed", 1},
      {"Mesh.Algorithm", 6},    // Frontal-Delaunay
      {"Mesh.Algorithm3D", 1},  // Delaunay
      {"Mesh.ElementOrder", 1},
      {"Mesh.RecombineAll", 0},
      {"Mesh.SubdivisionAlgorithm", 0},
      {"Mesh.MeshSizeFactor", 1},
      {"Mesh.MeshSizeMin", 0},
      {"Mesh.MeshSizeMax", 1e22},
      {"Mesh.MeshSizeFromPoints", 1},
      {"Mesh.MeshSizeFromCurvature", 0},
      {"Mesh.MeshSizeExtendFromBoundary", 1},
      {"Mesh.ScalingFactor", 1},
      {"Mesh.Optimize", 1},
      {"Mesh.OptimizeNetgen", 0},
      {"Mesh.Smoothing", 1},
      {"Mesh.SaveAll", 0},
      {"Mesh.Binary", 0},
      {"Mesh.MshFileVersion", 4.1},
      {"Geometry.OCCScaling", 1},
  };
  for (const auto& [name, value] : options) gmsh::option::setNumber(name, value);
}

std::string exception_text() {
  try {
    throw;
  } catch (const std::string& s) {
    return s;
  } catch (const char* s) {
    return s ? s : "unknown Gmsh error";
  } catch (const std::exception& e) {
    return e.what();
  } catch (int code) {
    return fmt::format("Gmsh error code {}", code);
  } catch (...) {
    return "unknown Gmsh error";
  }
}

// ---- Conversion helpers --------------------------------------------------------------------

constexpr int kLine = 1;
constexpr int kTriangle = 2;
constexpr int kTetrahedron = 4;

std::string element_type_name(int type) {
  std::string name;
  int dim = 0, order = 0, n_nodes = 0, n_primary = 0;
  std::vector<double> local_coordinates;
  try {
    gmsh::model::mesh::getElementProperties(type, name, dim, order, n_nodes, local_coordinates,
                                            n_primary);
  } catch (...) {
    return "unknown element";
  }
  return name.empty() ? "unknown element" : name;
}

// Gmsh tag (node or element) -> position in a list; dense when the tags are compact.
class TagIndex {
 public:
  explicit TagIndex(const std::vector<std::size_t>& tags) {
    std::size_t max_tag = 0;
    for (const auto t : tags) max_tag = std::max(max_tag, t);
    dense_ = max_tag <= 4 * tags.size() + 1024;
    if (dense_) {
      table_.assign(max_tag + 1, -1);
      for (std::size_t i = 0; i < tags.size(); ++i) table_[tags[i]] = static_cast<std::int64_t>(i);
    } else {
      map_.reserve(tags.size());
      for (std::size_t i = 0; i < tags.size(); ++i) map_.emplace(tags[i], i);
    }
  }
  /// Position of `tag`, or -1.
  std::int64_t find(std::size_t tag) const {
    if (dense_) return tag < table_.size() ? table_[tag] : -1;
    const auto it = map_.find(tag);
    return it == map_.end() ? -1 : static_cast<std::int64_t>(it->second);
  }

 private:
  bool dense_ = true;
  std::vector<std::int64_t> table_;
  std::unordered_map<std::size_t, std::size_t> map_;
};

std::string group_name(int dim, int tag) {
  std::string name;
  gmsh::model::getPhysicalName(dim, tag, name);
  return name.empty() ? "group_" + std::to_string(tag) : name;
}

}  // namespace

// ---- GmshSession ---------------------------------------------------------------------------

GmshSession::GmshSession(std::string source) : source_(std::move(source)) {
  if (this_thread_in_session)
    throw InternalError(source_ + ": nested Gmsh session (a Gmsh session is already open)");
  lock_ = std::unique_lock<std::mutex>(gmsh_mutex());
  initialize_gmsh_once();
  try {
    reset_options();
    gmsh::logger::stop();  // in case a previous user left it running
    gmsh::logger::start();
    gmsh::clear();
  } catch (...) {
    throw Error(source_ + ": could not prepare Gmsh: " + exception_text());
  }
  this_thread_in_session = true;
}

GmshSession::~GmshSession() {
  try {
    gmsh::clear();
    gmsh::logger::stop();
  } catch (...) {
  }
  this_thread_in_session = false;
}

void GmshSession::check_log() {
  std::vector<std::string> log;
  try {
    gmsh::logger::get(log);
  } catch (...) {
    return;
  }
  std::vector<std::string> errors;
  for (std::size_t i = log_seen_; i < log.size(); ++i) {
    const std::string& line = log[i];
    for (const char* prefix : {"Error: ", "Fatal: "}) {
      if (line.rfind(prefix, 0) == 0) errors.push_back(line.substr(std::strlen(prefix)));
    }
    if (line.rfind("Warning: ", 0) == 0) log::debug("Gmsh ({}): {}", source_, line);
  }
  log_seen_ = log.size();
  if (errors.empty()) return;
  // "Could not merge file '<path>'" only repeats that the read failed: keep the others.
  if (errors.size() > 1)
    std::erase_if(errors,
                  [](const std::string& e) { return e.rfind("Could not merge file", 0) == 0; });
  constexpr std::size_t kShown = 3;
  std::string message;
  for (std::size_t i = 0; i < std::min(errors.size(), kShown); ++i)
    message += (i ? "; " : "") + errors[i];
  if (errors.size() > kShown)
    message += fmt::format(" (and {} more errors)", errors.size() - kShown);
  throw InputError(source_ + ": " + message);
}

void GmshSession::rethrow_as_input_error() {
  try {
    throw;
  } catch (const coapt::Error&) {
    throw;
  } catch (...) {
    const std::string text = exception_text();
    check_log();  // Gmsh's own error messages are the informative ones
    throw InputError(source_ + ": " + text);
  }
}

// ---- Conversion ----------------------------------------------------------------------------

Mesh mesh_from_gmsh_model(const std::string& source) {
  auto fail = [&](const std::string& message) -> InputError {
    return InputError(source + ": " + message);
  };

  Mesh mesh;
  mesh.source = source;
  mesh.comm = MPI_COMM_SELF;
  {
    std::vector<int> types_3d;
    gmsh::model::mesh::getElementTypes(types_3d, 3);
    mesh.dim = types_3d.empty() ? 2 : 3;
  }
  const int dim = mesh.dim;
  const int per_cell = dim + 1;
  const int cell_type = dim == 2 ? kTriangle : kTetrahedron;
  const int facet_type = dim == 2 ? kLine : kTriangle;
  const char* cell_kind = dim == 2 ? "3-node triangles" : "4-node tetrahedra";

  // Cells, entity by entity, each with its entity's physical group.
  std::vector<std::size_t> cell_element;  // element tags
  std::vector<std::size_t> cell_nodes;    // node tags, per_cell per cell
  std::vector<int> cell_group;
  gmsh::vectorpair entities;
  gmsh::model::getEntities(entities, dim);
  for (const auto& [entity_dim, entity] : entities) {
    std::vector<int> physicals;
    gmsh::model::getPhysicalGroupsForEntity(entity_dim, entity, physicals);
    if (physicals.size() > 1)
      throw fail(fmt::format(
          "{}D entity {} belongs to {} physical groups ('{}' and '{}'); a cell can have only one",
          entity_dim, entity, physicals.size(), group_name(entity_dim, physicals[0]),
          group_name(entity_dim, physicals[1])));
    const int group = physicals.empty() ? 0 : physicals[0];
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> element_tags, node_tags;
    gmsh::model::mesh::getElements(types, element_tags, node_tags, entity_dim, entity);
    for (std::size_t t = 0; t < types.size(); ++t) {
      if (element_tags[t].empty()) continue;
      if (types[t] != cell_type)
        throw fail(fmt::format(
            "element {} is a {} (Gmsh element type {}); coapt reads only {} in a {}D mesh",
            element_tags[t].front(), element_type_name(types[t]), types[t], cell_kind, dim));
      if (node_tags[t].size() != element_tags[t].size() * per_cell)
        throw fail(fmt::format("inconsistent node list for the elements of {}D entity {}",
                               entity_dim, entity));
      cell_element.insert(cell_element.end(), element_tags[t].begin(), element_tags[t].end());
      cell_nodes.insert(cell_nodes.end(), node_tags[t].begin(), node_tags[t].end());
      cell_group.insert(cell_group.end(), element_tags[t].size(), group);
    }
  }
  const std::size_t n_cells = cell_element.size();
  if (n_cells == 0) throw fail("the mesh has no triangles or tetrahedra (is it a mesh file?)");
  if (n_cells > static_cast<std::size_t>(INT_MAX / per_cell))
    throw fail(fmt::format("{} cells is more than coapt's 32-bit indices can hold", n_cells));

  // Cells in order of element tag.
  std::vector<std::size_t> order(n_cells);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return cell_element[a] < cell_element[b]; });

  // Nodes: the ones the cells use, numbered in increasing tag.
  std::vector<std::size_t> node_tags;
  std::vector<double> node_coordinates, parametric;
  gmsh::model::mesh::getNodes(node_tags, node_coordinates, parametric, -1, -1, false, false);
  const TagIndex node_index(node_tags);
  std::vector<char> used(node_tags.size(), 0);
  std::vector<std::int64_t> cell_position(cell_nodes.size());  // position in node_tags
  for (std::size_t i = 0; i < cell_nodes.size(); ++i) {
    const std::int64_t position = node_index.find(cell_nodes[i]);
    if (position < 0)
      throw fail(fmt::format("element {} uses node {}, which is not defined",
                             cell_element[i / per_cell], cell_nodes[i]));
    used[static_cast<std::size_t>(position)] = 1;
    cell_position[i] = position;
  }
  std::vector<std::size_t> used_positions;
  for (std::size_t p = 0; p < node_tags.size(); ++p)
    if (used[p]) used_positions.push_back(p);
  std::sort(used_positions.begin(), used_positions.end(),
            [&](std::size_t a, std::size_t b) { return node_tags[a] < node_tags[b]; });
  const int n_vertices = static_cast<int>(used_positions.size());
  std::vector<int> local_of_position(node_tags.size(), -1);
  for (int v = 0; v < n_vertices; ++v) local_of_position[used_positions[v]] = v;

  if (dim == 2) {  // must lie in z = 0
    double extent = 0, lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (const auto p : used_positions)
      for (int d = 0; d < 2; ++d) {
        lo[d] = std::min(lo[d], node_coordinates[3 * p + d]);
        hi[d] = std::max(hi[d], node_coordinates[3 * p + d]);
      }
    extent = std::max(hi[0] - lo[0], hi[1] - lo[1]);
    const double tolerance = 1e-10 * extent;
    for (const auto p : used_positions) {
      const double z = node_coordinates[3 * p + 2];
      if (!(std::abs(z) <= tolerance))
        throw fail(fmt::format("a 2D mesh must lie in the plane z = 0, but node {} is at z = {:g}",
                               node_tags[p], z));
    }
  }

  mesh.coordinates.resize(static_cast<std::size_t>(n_vertices) * dim);
  mesh.original_vertex.resize(n_vertices);
  for (int v = 0; v < n_vertices; ++v) {
    const std::size_t p = used_positions[v];
    for (int d = 0; d < dim; ++d) mesh.coordinates[v * dim + d] = node_coordinates[3 * p + d];
    mesh.original_vertex[v] = static_cast<std::int64_t>(node_tags[p]);
  }
  mesh.global_vertex.resize(n_vertices);
  std::iota(mesh.global_vertex.begin(), mesh.global_vertex.end(), PetscInt{0});
  mesh.n_owned_vertices = n_vertices;
  mesh.vertex_offset = 0;
  mesh.n_global_vertices = n_vertices;

  mesh.cells.resize(n_cells * per_cell);
  mesh.cell_tags.resize(n_cells);
  mesh.original_cell.resize(n_cells);
  for (std::size_t c = 0; c < n_cells; ++c) {
    const std::size_t from = order[c];
    for (int k = 0; k < per_cell; ++k)
      mesh.cells[c * per_cell + k] =
          local_of_position[static_cast<std::size_t>(cell_position[from * per_cell + k])];
    mesh.cell_tags[c] = cell_group[from];
    mesh.original_cell[c] = static_cast<std::int64_t>(cell_element[from]);
  }
  mesh.n_owned_cells = static_cast<int>(n_cells);
  mesh.n_global_cells = static_cast<std::int64_t>(n_cells);

  // Groups: the mesh dimension's (cells), then dim - 1 (facets).
  gmsh::vectorpair cell_groups, facet_groups;
  gmsh::model::getPhysicalGroups(cell_groups, dim);
  gmsh::model::getPhysicalGroups(facet_groups, dim - 1);
  std::sort(cell_groups.begin(), cell_groups.end());
  std::sort(facet_groups.begin(), facet_groups.end());
  for (const auto& groups : {cell_groups, facet_groups})
    for (const auto& [group_dim, tag] : groups)
      mesh.groups.push_back({group_name(group_dim, tag), group_dim, tag});

  // Boundary facets: every element of every facet group.
  std::vector<std::size_t> facet_element;  // element tag, for messages
  std::vector<std::string> facet_group_name;
  for (const auto& [group_dim, tag] : facet_groups) {
    const std::string name = group_name(group_dim, tag);
    // An element listed twice in a group is kept once: MSH 2 files repeat the elements of an
    // entity that belongs to several physical groups (with new element tags).
    std::set<std::array<std::size_t, 3>> seen;
    std::vector<int> group_entities;
    gmsh::model::getEntitiesForPhysicalGroup(group_dim, tag, group_entities);
    for (const int entity : group_entities) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> element_tags, element_nodes;
      gmsh::model::mesh::getElements(types, element_tags, element_nodes, group_dim, entity);
      for (std::size_t t = 0; t < types.size(); ++t) {
        if (element_tags[t].empty()) continue;
        if (types[t] != facet_type)
          throw fail(fmt::format(
              "element {} of physical group '{}' is a {} (Gmsh element type {}); the boundary "
              "groups of a {}D mesh must be made of {}",
              element_tags[t].front(), name, element_type_name(types[t]), types[t], dim,
              dim == 2 ? "2-node lines" : "3-node triangles"));
        for (std::size_t e = 0; e < element_tags[t].size(); ++e) {
          std::array<std::size_t, 3> key{0, 0, 0};
          std::copy_n(element_nodes[t].begin() + static_cast<std::ptrdiff_t>(e * dim), dim,
                      key.begin());
          std::sort(key.begin(), key.end());  // node tags are > 0: the 2D padding stays first
          if (!seen.insert(key).second) continue;
          for (int k = 0; k < dim; ++k) {
            const std::int64_t position = node_index.find(element_nodes[t][e * dim + k]);
            mesh.facets.push_back(
                position < 0 ? -1 : local_of_position[static_cast<std::size_t>(position)]);
          }
          mesh.facet_tags.push_back(tag);
          facet_element.push_back(element_tags[t][e]);
          facet_group_name.push_back(name);
        }
      }
    }
  }
  mesh.facet_cell = find_facet_cells(mesh, mesh.facets);
  for (std::size_t f = 0; f < mesh.facet_cell.size(); ++f) {
    if (mesh.facet_cell[f] < 0)
      throw fail(fmt::format("boundary element {} (physical group '{}') is not a face of any {}",
                             facet_element[f], facet_group_name[f],
                             dim == 2 ? "triangle" : "tetrahedron"));
    orient_facet_outward(mesh, mesh.facet_cell[f],
                         std::span<int>(mesh.facets.data() + f * dim, dim));
  }

  orient_cells(mesh);
  return mesh;
}

// ---- Reader --------------------------------------------------------------------------------

Mesh read_gmsh(const std::string& path) {
  namespace fs = std::filesystem;
  // Gmsh opens a missing file as an empty model without an error: check it ourselves.
  std::error_code error;
  const auto status = fs::status(path, error);
  if (!fs::exists(status)) throw InputError(path + ": cannot open the mesh file: no such file");
  if (fs::is_directory(status))
    throw InputError(path + ": cannot open the mesh file: it is a directory");
  {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw InputError(path + ": cannot open the mesh file: " + std::strerror(errno));
    if (file.peek() == std::ifstream::traits_type::eof())
      throw InputError(path + ": the mesh file is empty");
  }

  GmshSession session(path);
  // merge, not open: gmsh::open takes a lock that stays held if the read fails, after which
  // every later open is silently ignored ("I'm busy! Ask me that later...").
  session.run([&] { gmsh::merge(path); });
  Mesh mesh;
  session.run([&] { mesh = mesh_from_gmsh_model(path); });
  return mesh;
}

}  // namespace coapt::mesh
