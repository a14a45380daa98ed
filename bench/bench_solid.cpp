// coapt-bench solid: Newton iterations of the finite-strain solid (SolidModel, P1, total
// Lagrangian) on a nearly incompressible Neo-Hookean block: the unit cube with n³ cubes of 6
// tetrahedra (n = 44: 511 104 tets), μ = 100 kPa, κ = 5000 μ (ν ≈ 0.4999), clamped at x = 0 and
// pulled down by a dead traction of 1 kPa on x = 1, in one load step. Reported: wall time per
// Newton iteration, split into assembly (residual and tangent) and linear solve, with the
// solver of the options (displacement formulation: default GMRES + GAMG with the rigid-body
// near-null space; --formulation mixed: the P1-P1 displacement-pressure form with its default
// GMRES + fieldsplit Schur preconditioner of solid/mixed_solver.hpp, or MUMPS LU with
// -- -solid_ksp_type preonly -solid_pc_type lu; PETSc options with the prefix solid_ after --),
// and the Krylov iterations per Newton iteration.

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>

#include "bench_common.hpp"
#include "coapt/core/config.hpp"
#include "coapt/core/log.hpp"
#include "coapt/run/run_output.hpp"
#include "coapt/solid/solid_model.hpp"

namespace coapt::bench {
namespace {

/// Largest value over the ranks (collective).
double max_over_ranks(MPI_Comm comm, double value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm);
  return value;
}

}  // namespace

io::Json solid(const Context& context, const SolidBenchOptions& options) {
  const MPI_Comm comm = context.comm();
  const std::string text = fmt::format(R"(problem: solid
mesh: {{type: box, lower: [0, 0, 0], upper: [1, 1, 1], cells: [{0}, {0}, {0}]}}
bodies:
  - name: block
    material: {{model: nearly_incompressible_neo_hookean, shear_modulus: 1.0e5, bulk_modulus: 5.0e8}}
dirichlet:
  - {{boundary: left}}
tractions:
  - {{boundary: right, traction: [0, 0, -1000]}}
formulation: {1}
output: {{vtk: false}}
)",
                                       options.n, options.formulation);
  auto document = config::Document::from_string(text, "coapt-bench solid");
  const double setup_start = MPI_Wtime();
  solid::SolidModel model(document.root(), comm);
  const double setup = max_over_ranks(comm, MPI_Wtime() - setup_start);
  model.describe();
  const auto directory =
      std::filesystem::temp_directory_path() / fmt::format("coapt-bench-solid-{}", ::getpid());
  run::RunOutput output(comm, directory, text, "coapt-bench solid", "coapt-bench solid");

  const double start = MPI_Wtime();
  const auto report = model.solve_static(1.0, output, "bench");
  const double total = max_over_ranks(comm, MPI_Wtime() - start);
  const auto& stages = output.timers().stages();
  const auto stage = [&](const char* name) {
    const auto it = stages.find(name);
    return max_over_ranks(comm, it == stages.end() ? 0.0 : it->second.seconds);
  };
  const double assemble = stage("assemble"), solve = stage("solve");
  const int iterations = std::max(1, report.newton_iterations);
  long long max_owned = model.mesh().n_owned_cells;
  MPI_Allreduce(MPI_IN_PLACE, &max_owned, 1, MPI_LONG_LONG, MPI_MAX, comm);
  log::info(
      "solid: {} tets on {} rank(s): {} Newton iterations, {} Krylov iterations; per Newton "
      "iteration {:.3f} s (assembly {:.3f} s, solve {:.3f} s)",
      model.mesh().n_global_cells, context.size(), report.newton_iterations,
      report.linear_iterations, total / iterations, assemble / iterations, solve / iterations);

  io::Json figures = io::Json::object();
  figures["benchmark"] = "solid";
  figures["n"] = options.n;
  figures["formulation"] = options.formulation;
  figures["ranks"] = context.size();
  figures["tets"] = static_cast<std::int64_t>(model.mesh().n_global_cells);
  figures["dofs"] = static_cast<std::int64_t>((options.formulation == "mixed" ? 4 : 3) *
                                              model.mesh().n_global_vertices);
  figures["max_tets_per_rank"] = static_cast<std::int64_t>(max_owned);
  figures["setup_seconds"] = setup;
  figures["newton_iterations"] = report.newton_iterations;
  figures["krylov_iterations"] = report.linear_iterations;
  figures["seconds_per_newton_iteration"] = total / iterations;
  figures["assembly_seconds_per_newton_iteration"] = assemble / iterations;
  figures["solve_seconds_per_newton_iteration"] = solve / iterations;
  figures["krylov_per_newton_iteration"] =
      static_cast<double>(report.linear_iterations) / iterations;
  figures["final_residual"] = report.norm();
  std::error_code ignored;
  MPI_Barrier(comm);
  if (context.rank() == 0) std::filesystem::remove_all(directory, ignored);
  return figures;
}

}  // namespace coapt::bench
