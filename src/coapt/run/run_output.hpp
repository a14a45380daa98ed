#pragma once
/// @file run_output.hpp
/// The output folder of a run: case.yaml (the case as resolved), series.csv (one row per
/// step), summary.json (status, wall time per stage, iteration counts, the `benchmark`
/// object of verification cases), VTK series and log.txt. summary.json says "running" from
/// the start, so an interrupted run never looks complete, and "failed" with the reason
/// when the run fails.

#include <mpi.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "coapt/core/timer.hpp"
#include "coapt/io/csv_series.hpp"
#include "coapt/io/json.hpp"
#include "coapt/io/vtk_writer.hpp"

namespace coapt::run {

/// Owns the output folder of one run. Collective on `comm` for every call that writes.
class RunOutput {
 public:
  /// Creates `directory`, writes `resolved_case` to case.yaml, opens log.txt and writes a
  /// summary with status "running". `case_file` and `command` are recorded in the summary.
  RunOutput(MPI_Comm comm, std::filesystem::path directory, const std::string& resolved_case,
            const std::string& case_file, const std::string& command);
  RunOutput(const RunOutput&) = delete;
  RunOutput& operator=(const RunOutput&) = delete;
  ~RunOutput();

  const std::filesystem::path& directory() const { return directory_; }
  /// series.csv (created on first use).
  io::CsvSeries& series();
  /// The VTK series `name` (DIR/name.pvd; created on first use).
  io::VtkSeries& vtk(const std::string& name = "solution");
  /// The summary being built; "benchmark", "iterations" and other objects go in here.
  io::Json& summary() { return summary_; }
  /// Wall time per stage, written to the summary under "stages".
  StageTimers& timers() { return timers_; }
  /// Writes summary.json now (with the current status), e.g. after each step of a long run.
  void write_summary();
  /// Marks the run completed and writes the summary. A summary holding a non-finite number
  /// marks the run failed instead (non-finite values are written as null).
  void complete();
  /// Marks the run failed with `reason` and writes the summary.
  void fail(const std::string& reason);
  /// A step failed and the problem has written its last committed state (step `step`, at
  /// `time` [s]) into this folder with a checkpoint: records last_good_step and
  /// last_good_time in the summary and says in the log where it is and how to continue.
  void keep_last_good_state(int step, double time);
  /// Whether complete() or fail() was called.
  bool finished() const { return finished_; }

 private:
  MPI_Comm comm_;
  std::filesystem::path directory_;
  io::Json summary_;
  StageTimers timers_;
  std::unique_ptr<io::CsvSeries> series_;
  std::map<std::string, std::unique_ptr<io::VtkSeries>> vtk_;
  double start_ = 0.0;
  bool finished_ = false;
};

}  // namespace coapt::run
