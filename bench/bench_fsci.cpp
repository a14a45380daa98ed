// coapt-bench fsci: a coupled run (`problem: fsci`) of a case for a few time steps, e.g. the
// 2D valve (cases/valve2d.yaml: leaflets with contact, IQN-ILS) or a transient Turek-Hron
// FSI case, run as `coapt run` runs it (run::create_problem into a run folder), with the wall
// time per stage of the coupled problem from the run's timers: solid (the deformable solids'
// Newmark solves, contact included), contact (the contact hook's share of it), transfer
// (moving the solids and re-assembling the coupling operators B, D), fluid (the Navier-Stokes
// Newton solves), coupling (forces Bᵀλ and the relaxation or IQN-ILS update), checkpoint and
// output; per stage the slowest rank's seconds. `--set key=value` overrides case keys as for
// `coapt run`.

#include <fmt/format.h>
#include <mpi.h>

#include <filesystem>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "coapt/core/config.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/io/json.hpp"
#include "coapt/run/problem.hpp"
#include "coapt/run/run_output.hpp"

namespace coapt::bench {

io::Json fsci(const Context& context, const FsciBenchOptions& options) {
  const MPI_Comm comm = context.comm();
  auto document = config::Document::from_file(options.case_file);
  document.set(fmt::format("mesh.level={}", options.level));
  document.set("output.vtk=false");
  for (const auto& assignment : options.assignments) document.set(assignment);
  if (options.steps > 0) {
    auto root = document.root();
    const double step =
        root.section("time", "time stepping").require<double>("step", {"s", "time step"});
    document.set(fmt::format("time.end_time={:.17g}", options.steps * step));
  }
  auto problem = run::create_problem(document.root(), comm);
  document.reject_unknown_keys();
  run::RunOutput output(comm, options.output, document.resolved_yaml(), options.case_file,
                        "coapt-bench fsci");
  const double start = MPI_Wtime();
  problem->run(output);
  double total = MPI_Wtime() - start;
  MPI_Allreduce(MPI_IN_PLACE, &total, 1, MPI_DOUBLE, MPI_MAX, comm);
  output.complete();

  io::Json figures = io::Json::object();
  figures["case"] = std::filesystem::path(options.case_file).filename().string();
  figures["level"] = options.level;
  figures["ranks"] = size_of(comm);
  figures["steps"] = options.steps;
  const auto& iterations = output.summary()["iterations"];
  figures["coupling_iterations"] = iterations.at("coupling");
  figures["fluid_newton_iterations"] = iterations.at("newton");
  figures["total_s"] = total;
  std::string line;
  for (const char* name :
       {"solid", "contact", "transfer", "fluid", "coupling", "checkpoint", "output"}) {
    const auto& stages = output.timers().stages();
    const auto found = stages.find(name);
    double seconds = found == stages.end() ? 0.0 : found->second.seconds;
    MPI_Allreduce(MPI_IN_PLACE, &seconds, 1, MPI_DOUBLE, MPI_MAX, comm);
    figures[fmt::format("{}_s", name)] = seconds;
    line += fmt::format(" {} {:.3f} s,", name, seconds);
  }
  log::info("fsci {} level {} on {} rank(s), {} step(s): total {:.3f} s;{}", options.case_file,
            options.level, size_of(comm), options.steps, total, line);
  return figures;
}

}  // namespace coapt::bench
