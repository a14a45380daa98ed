#include "coapt/io/vtk_writer.hpp"

#include <fmt/format.h>

#include <bit>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <system_error>

#include "coapt/core/error.hpp"

namespace coapt::io {

namespace {

constexpr const char* kByteOrder =
    std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
constexpr std::uint8_t kVtkTriangle = 5;
constexpr std::uint8_t kVtkTetra = 10;

// ---------------------------------------------------------------------------------------
// Collective failure handling: every rank states what (if anything) went wrong locally;
// all ranks then throw the message of the lowest failing rank, or all go on.

enum class FailureKind : int { none = 0, error = 1, internal = 2 };

struct Failure {
  FailureKind kind = FailureKind::none;
  std::string message;
  void set(FailureKind k, std::string text) {
    if (kind != FailureKind::none) return;  // keep the first
    kind = k;
    message = std::move(text);
  }
  void internal(std::string text) { set(FailureKind::internal, std::move(text)); }
  void error(std::string text) { set(FailureKind::error, std::move(text)); }
};

void throw_if_any(MPI_Comm comm, int rank, const Failure& failure) {
  const int mine = failure.kind == FailureKind::none ? INT_MAX : rank;
  int first = INT_MAX;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == INT_MAX) return;
  long long header[2] = {static_cast<long long>(failure.kind),
                         static_cast<long long>(failure.message.size())};
  MPI_Bcast(header, 2, MPI_LONG_LONG, first, comm);
  std::string message = rank == first ? failure.message : std::string(header[1], '\0');
  MPI_Bcast(message.data(), static_cast<int>(header[1]), MPI_CHAR, first, comm);
  if (static_cast<FailureKind>(header[0]) == FailureKind::internal) throw InternalError(message);
  throw Error(message);
}

/// 64-bit FNV-1a, the same on every rank (unlike std::hash, which need not be).
std::uint64_t fnv1a(std::string_view text) {
  std::uint64_t h = 14695981039346656037ull;
  for (const char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

/// Writes `content` to `path`; returns an empty string or what went wrong.
std::string write_file(const std::filesystem::path& path, std::string_view content) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file)
    return fmt::format("cannot open {} for writing: {}", path.string(), std::strerror(errno));
  const std::size_t written = std::fwrite(content.data(), 1, content.size(), file);
  const int write_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (written != content.size())
    return fmt::format("cannot write {}: {}", path.string(), std::strerror(write_errno));
  if (!closed) return fmt::format("cannot write {}: {}", path.string(), std::strerror(errno));
  return {};
}

/// Writes `content` to a temporary file beside `path`, then renames it to `path`, so that a
/// reader (or a crash) never sees a half-written file.
std::string write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  std::filesystem::path temporary = path;
  temporary += ".tmp";
  if (std::string problem = write_file(temporary, content); !problem.empty()) return problem;
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec)
    return fmt::format("cannot rename {} to {}: {}", temporary.string(), path.string(),
                       ec.message());
  return {};
}

/// Text for an XML attribute value in double quotes.
std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      case '\n':
        out += "&#10;";
        break;
      case '\t':
        out += "&#9;";
        break;
      case '\r':
        out += "&#13;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// A double written so that it reads back exactly.
std::string exact(double value) {
  return fmt::format("{}", value);
}

template <class T>
constexpr const char* vtk_type_name() {
  if constexpr (std::is_same_v<T, double>) return "Float64";
  if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  if constexpr (std::is_same_v<T, std::uint8_t>) return "UInt8";
}

/// Appends <DataArray ...>base64(UInt64 byte count, data)</DataArray> to `xml`.
template <class T>
void append_data_array(std::string& xml, std::string_view indent, std::string_view name,
                       int n_components, const std::vector<T>& data,
                       std::string_view extra_attributes = {}) {
  const std::uint64_t n_bytes = data.size() * sizeof(T);
  std::vector<std::byte> bytes(sizeof(n_bytes) + n_bytes);
  std::memcpy(bytes.data(), &n_bytes, sizeof(n_bytes));
  if (n_bytes > 0) std::memcpy(bytes.data() + sizeof(n_bytes), data.data(), n_bytes);
  xml += indent;
  xml += fmt::format("<DataArray type=\"{}\"", vtk_type_name<T>());
  if (!name.empty()) xml += fmt::format(" Name=\"{}\"", xml_escape(name));
  xml += fmt::format(" NumberOfComponents=\"{}\"{} format=\"binary\">", n_components,
                     extra_attributes);
  xml += detail::base64_encode(bytes);
  xml += "</DataArray>\n";
}

/// One array of a piece, gathered and padded.
struct GatheredField {
  std::string name;
  int n_components = 1;  ///< as written (after padding)
  Field::Location location = Field::Location::vertex;
  std::vector<double> values;
};

/// Components written for a field of `n` components on a mesh of dimension `dim`.
int written_components(int dim, int n) {
  return dim == 2 && n == 2 ? 3 : n;
}

}  // namespace

namespace detail {

std::string base64_encode(std::span<const std::byte> bytes) {
  static constexpr char alphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t triple = std::to_integer<std::uint32_t>(bytes[i]) << 16 |
                                 std::to_integer<std::uint32_t>(bytes[i + 1]) << 8 |
                                 std::to_integer<std::uint32_t>(bytes[i + 2]);
    out += alphabet[(triple >> 18) & 63];
    out += alphabet[(triple >> 12) & 63];
    out += alphabet[(triple >> 6) & 63];
    out += alphabet[triple & 63];
  }
  const std::size_t rest = bytes.size() - i;
  if (rest > 0) {
    std::uint32_t triple = std::to_integer<std::uint32_t>(bytes[i]) << 16;
    if (rest == 2) triple |= std::to_integer<std::uint32_t>(bytes[i + 1]) << 8;
    out += alphabet[(triple >> 18) & 63];
    out += alphabet[(triple >> 12) & 63];
    out += rest == 2 ? alphabet[(triple >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

}  // namespace detail

VtkSeries::VtkSeries(MPI_Comm comm, std::filesystem::path directory, std::string base_name)
    : comm_(comm), directory_(std::move(directory)), base_name_(std::move(base_name)) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  Failure failure;
  if (base_name_.empty() || base_name_.find('/') != std::string::npos)
    failure.error(
        fmt::format("VTK output: invalid base name '{}' (empty or containing '/')", base_name_));
  else if (rank_ == 0) {
    std::error_code ec;
    const auto pieces = directory_ / (base_name_ + "_pieces");
    std::filesystem::create_directories(pieces, ec);
    if (ec || !std::filesystem::is_directory(pieces))
      failure.error(fmt::format("VTK output: cannot create the directory {}: {}", pieces.string(),
                                ec ? ec.message() : "not a directory"));
  }
  throw_if_any(comm_, rank_, failure);
}

std::filesystem::path VtkSeries::pvd_path() const {
  return directory_ / (base_name_ + ".pvd");
}

std::filesystem::path VtkSeries::pvtu_path(int step) const {
  return directory_ / fmt::format("{}_{:06d}.pvtu", base_name_, step);
}

std::filesystem::path VtkSeries::piece_path(int step, int rank) const {
  return directory_ / (base_name_ + "_pieces") /
         fmt::format("{}_{:06d}_r{:04d}.vtu", base_name_, step, rank);
}

void VtkSeries::write(const mesh::Mesh& mesh, double time, std::span<const Field> fields) {
  const int step = n_steps();
  const std::string where = fmt::format("VTK output '{}' step {} (time {})",
                                        (directory_ / base_name_).string(), step, time);

  // 1. Consistency of the arguments (cheap checks; all collective below).
  Failure failure;
  {
    int comparison = MPI_UNEQUAL;
    MPI_Comm_compare(comm_, mesh.comm, &comparison);
    const int dim = mesh.dim;
    const std::size_t nv = mesh.global_vertex.size();
    if (comparison != MPI_IDENT && comparison != MPI_CONGRUENT)
      failure.internal(where + ": the mesh's communicator is not the series' communicator");
    else if (dim != 2 && dim != 3)
      failure.internal(fmt::format("{}: mesh dimension {} (must be 2 or 3)", where, dim));
    else if (mesh.coordinates.size() != nv * dim)
      failure.internal(fmt::format("{}: mesh has {} coordinates for {} vertices in {}D", where,
                                   mesh.coordinates.size(), nv, dim));
    else if (mesh.cells.size() % (dim + 1) != 0 || mesh.n_owned_cells < 0 ||
             mesh.n_owned_cells > mesh.n_cells())
      failure.internal(fmt::format("{}: mesh has {} cell entries and {} owned cells", where,
                                   mesh.cells.size(), mesh.n_owned_cells));
    else if (!std::isfinite(time))
      failure.error(fmt::format("{}: the time is not finite", where));
    if (failure.kind == FailureKind::none) {
      const std::size_t owned_entries = static_cast<std::size_t>(mesh.n_owned_cells) * (dim + 1);
      for (std::size_t i = 0; i < owned_entries; ++i)
        if (mesh.cells[i] < 0 || static_cast<std::size_t>(mesh.cells[i]) >= nv) {
          failure.internal(fmt::format("{}: owned cell {} has vertex index {} (mesh has {})", where,
                                       i / (dim + 1), mesh.cells[i], nv));
          break;
        }
    }
    for (std::size_t f = 0; f < fields.size() && failure.kind == FailureKind::none; ++f) {
      const Field& field = fields[f];
      const std::size_t nc = field.n_components > 0 ? field.n_components : 0;
      if (field.name.empty() || field.name == "rank" || field.name == "global_id")
        failure.internal(
            fmt::format("{}: invalid field name '{}' (empty or reserved)", where, field.name));
      else if (field.n_components < 1)
        failure.internal(
            fmt::format("{}: field '{}' has {} components", where, field.name, field.n_components));
      else if (field.location == Field::Location::vertex && field.values.size() != nv * nc)
        failure.internal(
            fmt::format("{}: vertex field '{}' has {} values, expected {} ({} "
                        "vertices x {} components)",
                        where, field.name, field.values.size(), nv * nc, nv, nc));
      else if (field.location == Field::Location::cell &&
               field.values.size() != static_cast<std::size_t>(mesh.n_owned_cells) * nc &&
               field.values.size() != static_cast<std::size_t>(mesh.n_cells()) * nc)
        failure.internal(fmt::format(
            "{}: cell field '{}' has {} values, expected {} (owned "
            "cells) or {} (all cells) x {} components",
            where, field.name, field.values.size(), mesh.n_owned_cells, mesh.n_cells(), nc));
      for (std::size_t g = 0; g < f; ++g)
        if (fields[g].name == field.name)
          failure.internal(fmt::format("{}: two fields named '{}'", where, field.name));
    }
  }
  throw_if_any(comm_, rank_, failure);

  // Every rank must describe the same arrays (the .pvtu lists rank 0's) and the same time.
  {
    std::string signature = fmt::format("{};{};", mesh.dim, std::bit_cast<std::uint64_t>(time));
    for (const Field& field : fields)
      signature += fmt::format("{}|{}|{};", field.name, field.n_components,
                               static_cast<int>(field.location));
    const std::uint64_t hash = fnv1a(signature);
    std::uint64_t low = 0, high = 0;
    MPI_Allreduce(&hash, &low, 1, MPI_UINT64_T, MPI_MIN, comm_);
    MPI_Allreduce(&hash, &high, 1, MPI_UINT64_T, MPI_MAX, comm_);
    if (low != high)
      throw InternalError(where +
                          ": the ranks do not pass the same time, mesh dimension and "
                          "fields (names, components, locations)");
  }

  // 2. Gather the piece: owned cells, the vertices they use (renumbered in local order).
  const int dim = mesh.dim;
  const int per_cell = dim + 1;
  const int n_owned_cells = mesh.n_owned_cells;
  std::vector<std::int64_t> compact(mesh.n_vertices(), -1);
  for (int c = 0; c < n_owned_cells; ++c)
    for (const int v : mesh.cell(c)) compact[v] = 0;
  std::vector<int> used;  // local index of each piece point
  for (int v = 0; v < mesh.n_vertices(); ++v)
    if (compact[v] == 0) {
      compact[v] = static_cast<std::int64_t>(used.size());
      used.push_back(v);
    }
  const std::size_t n_points = used.size();

  std::vector<double> points(3 * n_points, 0.0);
  std::vector<std::int64_t> global_id(n_points);
  for (std::size_t p = 0; p < n_points; ++p) {
    const auto x = mesh.point(used[p]);
    for (int d = 0; d < dim; ++d) points[3 * p + d] = x[d];
    global_id[p] = static_cast<std::int64_t>(mesh.global_vertex[used[p]]);
  }
  for (std::size_t i = 0; i < points.size() && failure.kind == FailureKind::none; ++i)
    if (!std::isfinite(points[i]))
      failure.error(fmt::format("{}: mesh coordinate {} of vertex {} (global {}) is {} on rank {}",
                                where, i % 3, used[i / 3], global_id[i / 3], points[i], rank_));

  std::vector<GatheredField> gathered;
  gathered.reserve(fields.size());
  for (const Field& field : fields) {
    GatheredField out{field.name, written_components(dim, field.n_components), field.location, {}};
    const int nc = field.n_components;
    const std::size_t n_entries = field.location == Field::Location::vertex
                                      ? n_points
                                      : static_cast<std::size_t>(n_owned_cells);
    out.values.assign(n_entries * out.n_components, 0.0);
    for (std::size_t e = 0; e < n_entries; ++e) {
      const std::size_t source = field.location == Field::Location::vertex ? used[e] : e;
      for (int k = 0; k < nc; ++k) {
        const double value = field.values[source * nc + k];
        if (!std::isfinite(value) && failure.kind == FailureKind::none) {
          const std::string entry =
              field.location == Field::Location::vertex
                  ? fmt::format("vertex {} (global {})", source, mesh.global_vertex[source])
                  : fmt::format("owned cell {}", source);
          failure.error(fmt::format(
              "{}: field '{}' has the non-finite value {} at {}, component {}, on rank {} "
              "(first bad entry on the lowest such rank); nothing of this step was written",
              where, field.name, value, entry, k, rank_));
        }
        out.values[e * out.n_components + k] = value;
      }
    }
    gathered.push_back(std::move(out));
  }
  throw_if_any(comm_, rank_, failure);

  // 3. The piece.
  std::vector<std::int64_t> connectivity(static_cast<std::size_t>(n_owned_cells) * per_cell);
  std::vector<std::int64_t> offsets(n_owned_cells);
  for (int c = 0; c < n_owned_cells; ++c) {
    const auto vertices = mesh.cell(c);
    for (int k = 0; k < per_cell; ++k)
      connectivity[static_cast<std::size_t>(c) * per_cell + k] = compact[vertices[k]];
    offsets[c] = static_cast<std::int64_t>(c + 1) * per_cell;
  }
  const std::vector<std::uint8_t> types(n_owned_cells, dim == 2 ? kVtkTriangle : kVtkTetra);
  const std::vector<std::int32_t> cell_rank(n_owned_cells, rank_);

  std::string xml;
  xml += "<?xml version=\"1.0\"?>\n";
  xml += fmt::format(
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{}\" "
      "header_type=\"UInt64\">\n",
      kByteOrder);
  xml += "  <UnstructuredGrid>\n";
  xml += "    <FieldData>\n";
  append_data_array(xml, "      ", "TimeValue", 1, std::vector<double>{time},
                    " NumberOfTuples=\"1\"");
  xml += "    </FieldData>\n";
  xml += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", n_points,
                     n_owned_cells);
  xml += "      <PointData>\n";
  for (const auto& f : gathered)
    if (f.location == Field::Location::vertex)
      append_data_array(xml, "        ", f.name, f.n_components, f.values);
  append_data_array(xml, "        ", "global_id", 1, global_id);
  xml += "      </PointData>\n";
  xml += "      <CellData>\n";
  for (const auto& f : gathered)
    if (f.location == Field::Location::cell)
      append_data_array(xml, "        ", f.name, f.n_components, f.values);
  append_data_array(xml, "        ", "rank", 1, cell_rank);
  xml += "      </CellData>\n";
  xml += "      <Points>\n";
  append_data_array(xml, "        ", "Points", 3, points);
  xml += "      </Points>\n";
  xml += "      <Cells>\n";
  append_data_array(xml, "        ", "connectivity", 1, connectivity);
  append_data_array(xml, "        ", "offsets", 1, offsets);
  append_data_array(xml, "        ", "types", 1, types);
  xml += "      </Cells>\n";
  xml += "    </Piece>\n";
  xml += "  </UnstructuredGrid>\n";
  xml += "</VTKFile>\n";
  if (std::string problem = write_file(piece_path(step, rank_), xml); !problem.empty())
    failure.error(fmt::format("{}: {} (rank {})", where, problem, rank_));
  throw_if_any(comm_, rank_, failure);

  // 4. The .pvtu and the .pvd (rank 0).
  const std::string pvtu_file = pvtu_path(step).filename().string();
  if (rank_ == 0) {
    std::string p;
    p += "<?xml version=\"1.0\"?>\n";
    p += fmt::format(
        "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"{}\" "
        "header_type=\"UInt64\">\n",
        kByteOrder);
    p += "  <PUnstructuredGrid GhostLevel=\"0\">\n";
    p += "    <PFieldData>\n";
    p += "      <PDataArray type=\"Float64\" Name=\"TimeValue\" NumberOfComponents=\"1\"/>\n";
    p += "    </PFieldData>\n";
    p += "    <PPointData>\n";
    for (const auto& f : gathered)
      if (f.location == Field::Location::vertex)
        p += fmt::format(
            "      <PDataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\"/>\n",
            xml_escape(f.name), f.n_components);
    p += "      <PDataArray type=\"Int64\" Name=\"global_id\" NumberOfComponents=\"1\"/>\n";
    p += "    </PPointData>\n";
    p += "    <PCellData>\n";
    for (const auto& f : gathered)
      if (f.location == Field::Location::cell)
        p += fmt::format(
            "      <PDataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\"/>\n",
            xml_escape(f.name), f.n_components);
    p += "      <PDataArray type=\"Int32\" Name=\"rank\" NumberOfComponents=\"1\"/>\n";
    p += "    </PCellData>\n";
    p += "    <PPoints>\n";
    p += "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n";
    p += "    </PPoints>\n";
    for (int r = 0; r < size_; ++r)
      p += fmt::format(
          "    <Piece Source=\"{}\"/>\n",
          xml_escape(std::filesystem::relative(piece_path(step, r), directory_).generic_string()));
    p += "  </PUnstructuredGrid>\n";
    p += "</VTKFile>\n";
    if (std::string problem = write_file(pvtu_path(step), p); !problem.empty())
      failure.error(fmt::format("{}: {}", where, problem));

    if (failure.kind == FailureKind::none) {
      std::string c;
      c += "<?xml version=\"1.0\"?>\n";
      c += fmt::format("<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"{}\">\n",
                       kByteOrder);
      c += "  <Collection>\n";
      auto dataset = [&c](double t, const std::string& file) {
        c += fmt::format("    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
                         exact(t), xml_escape(file));
      };
      for (const Step& s : steps_) dataset(s.time, s.pvtu_file);
      dataset(time, pvtu_file);
      c += "  </Collection>\n";
      c += "</VTKFile>\n";
      if (std::string problem = write_file_atomically(pvd_path(), c); !problem.empty())
        failure.error(fmt::format("{}: {}", where, problem));
    }
  }
  throw_if_any(comm_, rank_, failure);
  steps_.push_back({time, pvtu_file});
}

}  // namespace coapt::io
