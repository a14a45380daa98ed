#pragma once
/// @file checkpoint.hpp
/// Checkpoints of a run, for `coapt run CASE.yaml --restart DIR`: a folder `DIR/checkpoint`
/// holding
///   state.json                 what the problem keeps besides fields (step, time, lumped
///                              states, histories) under "state", "ranks" (writers) and
///                              "fields" (components and the mesh's vertex and cell counts:
///                              a checkpoint of another mesh is refused)
///   <field>.<rank>.bin         per field and writing rank: its owned vertices' values keyed
///                              by the vertices' numbers in the mesh source (original_vertex)
///
/// Keying by source numbers makes a checkpoint independent of the partition: a run restarts
/// on any number of ranks (each rank reads the entries of its own vertices from every file);
/// on the same number of ranks with the same partition the restarted state is bit for bit the
/// written one. A checkpoint is written into `checkpoint.tmp` and renamed over the previous one
/// when complete, so a run that dies while writing leaves the last complete checkpoint.
///
/// Binary field file: "COAPTCK1", int64 n, int32 components, int64 ids[n], double values[n ×
/// components] (native byte order).
///
///   run::CheckpointWriter writer(comm, output.directory() / "checkpoint");
///   writer.state()["step"] = step;
///   writer.add_vertex_field("velocity", mesh, v, dim);
///   writer.commit();
///   run::CheckpointReader reader(comm, restart_directory / "checkpoint");
///   reader.read_vertex_field("velocity", mesh, v, dim);

#include <mpi.h>
#include <petscvec.h>

#include <filesystem>
#include <string>

#include "coapt/io/json.hpp"
#include "coapt/mesh/mesh.hpp"

namespace coapt::run {

/// Writes one checkpoint. Collective on `comm` for the constructor, add_vertex_field, commit.
class CheckpointWriter {
 public:
  /// Prepares `directory`.tmp (removing a stale one). `directory` is usually
  /// RunOutput::directory() / "checkpoint".
  CheckpointWriter(MPI_Comm comm, std::filesystem::path directory);
  /// What the problem keeps (rank 0's copy is written; every rank should hold the same).
  io::Json& state() { return state_; }
  /// The owned entries of a ghosted or plain vertex vector of `mesh` with `n_components`
  /// values per vertex (node-major). `name`: letters, digits, '_' only.
  void add_vertex_field(const std::string& name, const mesh::Mesh& mesh, Vec vector,
                        int n_components);
  /// Writes state.json and replaces the previous checkpoint by this one.
  void commit();

 private:
  MPI_Comm comm_;
  std::filesystem::path directory_, temporary_;
  io::Json state_;
  io::Json fields_;  ///< name -> components, vertices, cells of the mesh written
};

/// Reads one checkpoint. Throws InputError naming the folder or file when it is missing,
/// incomplete or does not match the mesh. Collective on `comm`.
class CheckpointReader {
 public:
  /// `directory`: a run folder (its `checkpoint` sub-folder is used) or the checkpoint folder.
  CheckpointReader(MPI_Comm comm, std::filesystem::path directory);
  const io::Json& state() const { return state_; }
  /// The checkpoint folder actually read.
  const std::filesystem::path& directory() const { return directory_; }
  /// Fills the owned entries of `vector` (and its ghosts, if it is ghosted) from the field
  /// `name`; every owned vertex of `mesh` must be in the checkpoint.
  void read_vertex_field(const std::string& name, const mesh::Mesh& mesh, Vec vector,
                         int n_components) const;

 private:
  MPI_Comm comm_;
  std::filesystem::path directory_;
  io::Json state_;
  io::Json fields_;  ///< name -> components, vertices, cells of the mesh written
  int writers_ = 0;
};

}  // namespace coapt::run
