#include "coapt/run/checkpoint.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "coapt/core/collective.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/petsc.hpp"
#include "coapt/fem/assembly.hpp"

namespace coapt::run {
namespace {

constexpr char kMagic[8] = {'C', 'O', 'A', 'P', 'T', 'C', 'K', '1'};

int rank_of(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

std::filesystem::path field_file(const std::filesystem::path& directory, const std::string& name,
                                 int rank) {
  return directory / fmt::format("{}.{}.bin", name, rank);
}

bool is_ghosted(Vec vector) {
  Vec local = nullptr;
  COAPT_PETSC_CHECK(VecGhostGetLocalForm(vector, &local));
  const bool ghosted = local != nullptr;
  if (ghosted) COAPT_PETSC_CHECK(VecGhostRestoreLocalForm(vector, &local));
  return ghosted;
}

/// Runs `work` on every rank; if it throws on any, every rank throws (an InputError when
/// some rank's failure was one).
template <class Work>
void run_everywhere(MPI_Comm comm, Work&& work) {
  std::string message;
  bool input = false;
  try {
    work();
  } catch (const InputError& e) {
    message = e.what();
    input = true;
  } catch (const Error& e) {
    message = e.what();
  }
  rethrow_collectively(comm, message, input);
}

}  // namespace

CheckpointWriter::CheckpointWriter(MPI_Comm comm, std::filesystem::path directory)
    : comm_(comm), directory_(std::move(directory)), temporary_(directory_) {
  temporary_ += ".tmp";
  run_on_root(comm_, [&] {
    std::error_code error;
    std::filesystem::remove_all(temporary_, error);
    if (!std::filesystem::create_directories(temporary_, error) || error)
      throw Error(fmt::format("cannot create the checkpoint folder {}: {}", temporary_.string(),
                              error ? error.message() : "it exists"));
  });
  state_ = io::Json::object();
  fields_ = io::Json::object();
}

void CheckpointWriter::add_vertex_field(const std::string& name, const mesh::Mesh& mesh, Vec vector,
                                        int n_components) {
  for (const char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_'))
      throw InternalError(fmt::format("checkpoint field name '{}' is not a plain word", name));
  PetscInt n_local = 0;
  COAPT_PETSC_CHECK(VecGetLocalSize(vector, &n_local));
  const std::int64_t n = mesh.n_owned_vertices;
  if (n_local != n * n_components)
    throw InternalError(fmt::format("checkpoint field '{}': {} local entries for {} vertices × {}",
                                    name, n_local, n, n_components));
  run_everywhere(comm_, [&] {
    const auto path = field_file(temporary_, name, rank_of(comm_));
    std::ofstream out(path, std::ios::binary);
    const std::int32_t components = n_components;
    out.write(kMagic, sizeof kMagic);
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
    out.write(reinterpret_cast<const char*>(&components), sizeof components);
    out.write(reinterpret_cast<const char*>(mesh.original_vertex.data()),
              static_cast<std::streamsize>(n * sizeof(std::int64_t)));
    const PetscScalar* values = nullptr;
    COAPT_PETSC_CHECK(VecGetArrayRead(vector, &values));
    out.write(reinterpret_cast<const char*>(values),
              static_cast<std::streamsize>(n_local * sizeof(double)));
    COAPT_PETSC_CHECK(VecRestoreArrayRead(vector, &values));
    if (!out) throw Error(fmt::format("cannot write the checkpoint file {}", path.string()));
  });
  fields_[name] = io::Json::object({{"components", n_components},
                                    {"vertices", static_cast<std::int64_t>(mesh.n_global_vertices)},
                                    {"cells", mesh.n_global_cells}});
}

void CheckpointWriter::commit() {
  int size = 0;
  MPI_Comm_size(comm_, &size);
  run_on_root(comm_, [&] {
    io::Json document = io::Json::object();
    document["format"] = "coapt checkpoint 1";
    document["ranks"] = size;
    document["fields"] = fields_;
    document["state"] = state_;
    {
      std::ofstream out(temporary_ / "state.json");
      out << document.dump(2) << '\n';
      if (!out) throw Error(fmt::format("cannot write {}", (temporary_ / "state.json").string()));
    }
    std::error_code error;
    std::filesystem::remove_all(directory_, error);
    std::filesystem::rename(temporary_, directory_, error);
    if (error)
      throw Error(fmt::format("cannot move the checkpoint into {}: {}", directory_.string(),
                              error.message()));
  });
}

CheckpointReader::CheckpointReader(MPI_Comm comm, std::filesystem::path directory)
    : comm_(comm), directory_(std::move(directory)) {
  if (!std::filesystem::exists(directory_ / "state.json") &&
      std::filesystem::exists(directory_ / "checkpoint" / "state.json"))
    directory_ /= "checkpoint";
  std::string text;
  run_on_root(comm_, [&] {
    const auto path = directory_ / "state.json";
    std::ifstream in(path);
    if (!in)
      throw InputError(
          fmt::format("{}: no checkpoint here (state.json is missing)", directory_.string()));
    std::stringstream buffer;
    buffer << in.rdbuf();
    text = buffer.str();
    try {
      (void)io::Json::parse(text);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", path.string(), e.what()));
    }
  });
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, comm_);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, 0, comm_);
  const io::Json document = io::Json::parse(text);
  const auto where = (directory_ / "state.json").string();
  if (!document.is_object() || !document.contains("format") || !document.contains("state") ||
      !document.contains("ranks") || document.at("format").as_string() != "coapt checkpoint 1")
    throw InputError(fmt::format("{}: not a coapt checkpoint", where));
  state_ = document.at("state");
  if (document.contains("fields")) fields_ = document.at("fields");
  writers_ = static_cast<int>(document.at("ranks").as_int());
}

void CheckpointReader::read_vertex_field(const std::string& name, const mesh::Mesh& mesh,
                                         Vec vector, int n_components) const {
  if (!fields_.is_object() || !fields_.contains(name))
    throw InputError(
        fmt::format("{}: the checkpoint has no field '{}'", directory_.string(), name));
  const auto& field = fields_.at(name);
  if (field.at("vertices").as_int() != mesh.n_global_vertices ||
      field.at("cells").as_int() != mesh.n_global_cells)
    throw InputError(fmt::format(
        "{}: field '{}' was written on a mesh of {} vertices and {} cells; {} has {} and {}",
        directory_.string(), name, field.at("vertices").as_int(), field.at("cells").as_int(),
        mesh.source, mesh.n_global_vertices, mesh.n_global_cells));
  // Which owned vertex each source number stands for.
  std::unordered_map<std::int64_t, int> wanted;
  wanted.reserve(static_cast<std::size_t>(mesh.n_owned_vertices));
  for (int v = 0; v < mesh.n_owned_vertices; ++v) wanted.emplace(mesh.original_vertex[v], v);
  std::vector<double> values(static_cast<std::size_t>(mesh.n_owned_vertices) * n_components);
  std::vector<char> found(static_cast<std::size_t>(mesh.n_owned_vertices), 0);
  run_everywhere(comm_, [&] {
    for (int writer = 0; writer < writers_; ++writer) {
      const auto path = field_file(directory_, name, writer);
      std::ifstream in(path, std::ios::binary);
      if (!in) throw InputError(fmt::format("{}: missing checkpoint file", path.string()));
      char magic[sizeof kMagic];
      std::int64_t n = 0;
      std::int32_t components = 0;
      in.read(magic, sizeof magic);
      in.read(reinterpret_cast<char*>(&n), sizeof n);
      in.read(reinterpret_cast<char*>(&components), sizeof components);
      if (!in || std::memcmp(magic, kMagic, sizeof kMagic) != 0 || n < 0)
        throw InputError(fmt::format("{}: not a coapt checkpoint field", path.string()));
      if (components != n_components)
        throw InputError(fmt::format("{}: {} components per vertex, expected {}", path.string(),
                                     components, n_components));
      std::vector<std::int64_t> ids(static_cast<std::size_t>(n));
      std::vector<double> data(static_cast<std::size_t>(n) * components);
      in.read(reinterpret_cast<char*>(ids.data()),
              static_cast<std::streamsize>(ids.size() * sizeof(std::int64_t)));
      in.read(reinterpret_cast<char*>(data.data()),
              static_cast<std::streamsize>(data.size() * sizeof(double)));
      if (!in) throw InputError(fmt::format("{}: truncated checkpoint file", path.string()));
      for (std::size_t k = 0; k < ids.size(); ++k) {
        const auto entry = wanted.find(ids[k]);
        if (entry == wanted.end()) continue;
        const std::size_t v = static_cast<std::size_t>(entry->second);
        std::copy_n(data.begin() + static_cast<std::ptrdiff_t>(k * components), components,
                    values.begin() + static_cast<std::ptrdiff_t>(v * components));
        found[v] = 1;
      }
    }
    for (int v = 0; v < mesh.n_owned_vertices; ++v)
      if (!found[static_cast<std::size_t>(v)])
        throw InputError(fmt::format(
            "{}: field '{}' has no value for vertex {} of {} (a checkpoint of another mesh?)",
            directory_.string(), name, mesh.original_vertex[v], mesh.source));
  });
  PetscScalar* data = nullptr;
  COAPT_PETSC_CHECK(VecGetArray(vector, &data));
  std::copy(values.begin(), values.end(), data);
  COAPT_PETSC_CHECK(VecRestoreArray(vector, &data));
  if (is_ghosted(vector)) fem::update_ghosts(vector);
}

}  // namespace coapt::run
