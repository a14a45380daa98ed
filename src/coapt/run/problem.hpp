#pragma once
/// @file problem.hpp
/// A problem is what a case runs (`problem:` key): it reads its parameters and loads its
/// meshes when created (so `coapt check` validates a case without solving), describes
/// itself, and runs into a RunOutput.

#include <fmt/format.h>
#include <mpi.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/core/error.hpp"
#include "coapt/run/checkpoint.hpp"
#include "coapt/run/run_output.hpp"

namespace coapt::run {

/// One kind of simulation. Created collectively; run() is collective.
class Problem {
 public:
  virtual ~Problem() = default;
  /// Logs sizes, mesh quality and the settings that matter (for `coapt check` and run logs).
  virtual void describe() const = 0;
  /// Runs to the end, writing into `output` (series, VTK, summary["benchmark"]).
  /// Throws coapt::Error on failure; the caller marks the run failed.
  virtual void run(RunOutput& output) = 0;
  /// Continues from the checkpoint of an earlier run (`coapt run CASE --restart DIR`); called
  /// after creation, before run(). Problems that write no checkpoints refuse.
  virtual void restart_from(const CheckpointReader& checkpoint) {
    throw InputError(fmt::format("--restart {}: this problem kind writes no checkpoints",
                                 checkpoint.directory().string()));
  }
};

/// A registered problem kind.
struct ProblemKind {
  std::string name;
  std::string doc;
  std::function<std::unique_ptr<Problem>(const config::Section& root, MPI_Comm comm)> create;
};

/// Every problem kind coapt knows.
const std::vector<ProblemKind>& problem_kinds();

/// Reads `problem:` from the case root and creates that problem (reading all its keys).
std::unique_ptr<Problem> create_problem(const config::Section& root, MPI_Comm comm);

}  // namespace coapt::run
