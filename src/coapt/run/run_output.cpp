#include "coapt/run/run_output.hpp"

#include <petscsys.h>

#include <chrono>
#include <ctime>
#include <fstream>

#include "coapt/core/collective.hpp"
#include "coapt/core/context.hpp"
#include "coapt/core/log.hpp"

namespace coapt::run {
namespace {

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  char text[32] = {};
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return text;
}

}  // namespace

RunOutput::RunOutput(MPI_Comm comm, std::filesystem::path directory,
                     const std::string& resolved_case, const std::string& case_file,
                     const std::string& command)
    : comm_(comm), directory_(std::move(directory)), start_(MPI_Wtime()) {
  run_on_root(comm_, [&] {
    std::error_code error;
    std::filesystem::create_directories(directory_, error);
    if (error)
      throw InputError(directory_.string() +
                       ": cannot create the output folder: " + error.message());
    // A previous run's summary must not survive into this one.
    std::filesystem::remove(directory_ / "summary.json", error);
    std::ofstream file(directory_ / "case.yaml");
    if (!file) throw InputError((directory_ / "case.yaml").string() + ": cannot write");
    file << "# " << case_file << " as resolved (defaults and --set applied)\n" << resolved_case;
  });
  log::add_file((directory_ / "log.txt").string());
  summary_["status"] = "running";
  summary_["case"] = case_file;
  summary_["command"] = command;
  summary_["coapt_version"] = COAPT_VERSION;
  summary_["ranks"] = size_of(comm_);
  summary_["started"] = utc_now();
  write_summary();
}

RunOutput::~RunOutput() {
  log::close_files();
}

io::CsvSeries& RunOutput::series() {
  if (!series_) series_ = std::make_unique<io::CsvSeries>(comm_, directory_ / "series.csv");
  return *series_;
}

io::VtkSeries& RunOutput::vtk(const std::string& name) {
  auto& series = vtk_[name];
  if (!series) series = std::make_unique<io::VtkSeries>(comm_, directory_, name);
  return *series;
}

void RunOutput::write_summary() {
  summary_["wall_time_seconds"] = MPI_Wtime() - start_;
  io::Json stages = io::Json::object();
  for (const auto& [name, entry] : timers_.stages()) {
    io::Json stage = io::Json::object();
    stage["seconds"] = entry.seconds;
    stage["calls"] = static_cast<std::int64_t>(entry.calls);
    stages[name] = stage;
  }
  summary_["stages"] = stages;
  run_on_root(comm_, [&] {
    const auto path = directory_ / "summary.json";
    const auto partial = directory_ / "summary.json.part";
    summary_.write_file(partial);
    std::filesystem::rename(partial, path);  // readers never see half a file
  });
}

void RunOutput::complete() {
  if (summary_.has_non_finite()) {
    fail("a reported quantity is not finite (written as null in summary.json)");
    return;
  }
  summary_["status"] = "completed";
  finished_ = true;
  write_summary();
}

void RunOutput::keep_last_good_state(int step, double time) {
  summary_["last_good_step"] = step;
  summary_["last_good_time"] = time;
  log::error("the last good state (step {}, t = {:g} s) is in {}: --restart {} continues from it",
             step, time, directory_.string(), directory_.string());
}

void RunOutput::fail(const std::string& reason) {
  summary_["status"] = "failed";
  summary_["reason"] = reason;
  finished_ = true;
  write_summary();
}

}  // namespace coapt::run
