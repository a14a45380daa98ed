// coapt-bench contact: the quasi-static sliding of two deformable plates
// (cases/contact/plates3d.yaml: press, then slide, frictionless mortar contact with the
// semi-smooth Newton, MUMPS LU) at a chosen mesh level and size. Reported per load step and
// in total: wall time, Newton iterations, the Newton iterations after which the active set
// changed and the nodes that changed, active nodes and the largest penetration; the wall time
// is split into assembly (residual with the contact update, tangent) and linear solve.
// --steps N runs only the first N load steps (the press and the start of the slide).

#include <fmt/format.h>
#include <petscsys.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "bench_common.hpp"
#include "coapt/contact/solid_contact.hpp"
#include "coapt/core/config.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/run/run_output.hpp"
#include "coapt/solid/solid_model.hpp"

namespace coapt::bench {
namespace {

double max_over_ranks(MPI_Comm comm, double value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm);
  return value;
}

/// MUMPS LU for the solid, as `coapt run` sets it for a case with contact, unless the
/// command line chose a solver.
void default_direct_solver() {
  PetscBool ksp = PETSC_FALSE, pc = PETSC_FALSE;
  COAPT_PETSC_CHECK(PetscOptionsHasName(nullptr, "solid_", "-ksp_type", &ksp));
  COAPT_PETSC_CHECK(PetscOptionsHasName(nullptr, "solid_", "-pc_type", &pc));
  if (ksp || pc) return;
  COAPT_PETSC_CHECK(PetscOptionsSetValue(nullptr, "-solid_ksp_type", "preonly"));
  COAPT_PETSC_CHECK(PetscOptionsSetValue(nullptr, "-solid_pc_type", "lu"));
  COAPT_PETSC_CHECK(PetscOptionsSetValue(nullptr, "-solid_pc_factor_mat_solver_type", "mumps"));
}

}  // namespace

io::Json contact(const Context& context, const ContactBenchOptions& options) {
  const MPI_Comm comm = context.comm();
  auto document = config::Document::from_file(options.case_file);
  document.set(fmt::format("mesh.level={}", options.level));
  if (options.size > 0) document.set(fmt::format("mesh.size={:.17g}", options.size));
  document.set("output.vtk=false");
  auto root = document.root();
  default_direct_solver();
  const auto contact_parameters = contact::ContactParameters::read(root);
  const double setup_start = MPI_Wtime();
  solid::SolidModel model(root, comm);
  contact::ContactHook hook(contact_parameters, model);
  model.set_hook(&hook);
  const double setup = max_over_ranks(comm, MPI_Wtime() - setup_start);
  model.describe();
  const auto directory =
      std::filesystem::temp_directory_path() / fmt::format("coapt-bench-contact-{}", ::getpid());
  run::RunOutput output(comm, directory, document.resolved_yaml(), options.case_file,
                        "coapt-bench contact");

  const int case_steps = model.parameters().steps;
  const int steps = options.steps > 0 ? std::min(options.steps, case_steps) : case_steps;
  std::vector<double> seconds, penetration;
  std::vector<int> newton, changes, node_changes, active;
  for (int step = 1; step <= steps; ++step) {
    const double factor = static_cast<double>(step) / case_steps;
    MPI_Barrier(comm);
    const double start = MPI_Wtime();
    const auto report =
        model.solve_static(factor, output, fmt::format("load step {}/{}", step, case_steps));
    seconds.push_back(max_over_ranks(comm, MPI_Wtime() - start));
    const auto& status = hook.constraints().status();
    newton.push_back(report.newton_iterations);
    changes.push_back(hook.active_set_change_iterations());
    node_changes.push_back(hook.active_set_node_changes());
    active.push_back(status.active);
    penetration.push_back(status.max_penetration);
    hook.log_status(fmt::format("load step {}/{}", step, case_steps));
  }
  double total = 0;
  int total_newton = 0, total_changes = 0;
  for (int k = 0; k < steps; ++k) {
    total += seconds[static_cast<std::size_t>(k)];
    total_newton += newton[static_cast<std::size_t>(k)];
    total_changes += changes[static_cast<std::size_t>(k)];
  }
  const auto& stages = output.timers().stages();
  const auto stage = [&](const char* name) {
    const auto it = stages.find(name);
    return max_over_ranks(comm, it == stages.end() ? 0.0 : it->second.seconds);
  };
  const auto& status = hook.constraints().status();
  log::info(
      "contact: {} tets on {} rank(s), {} load steps in {:.2f} s ({:.2f} s per step), {} Newton "
      "iterations, {} of them changed the active set; max penetration {:.3e} m (tolerance "
      "{:.3e} m)",
      model.mesh().n_global_cells, context.size(), steps, total, total / steps, total_newton,
      total_changes, *std::max_element(penetration.begin(), penetration.end()),
      status.gap_tolerance);

  io::Json figures = io::Json::object();
  figures["benchmark"] = "contact";
  figures["case"] = options.case_file;
  figures["level"] = options.level;
  figures["ranks"] = context.size();
  figures["tets"] = static_cast<std::int64_t>(model.mesh().n_global_cells);
  figures["dofs"] = static_cast<std::int64_t>(3 * model.mesh().n_global_vertices);
  figures["slave_nodes_constrained"] = status.constrained;
  figures["setup_seconds"] = setup;
  figures["steps"] = steps;
  figures["case_steps"] = case_steps;
  figures["final_load_factor"] = static_cast<double>(steps) / case_steps;
  figures["total_seconds"] = total;
  figures["seconds_per_step"] = total / steps;
  figures["seconds_per_newton_iteration"] = total / std::max(1, total_newton);
  figures["assembly_seconds"] = stage("assemble");
  figures["solve_seconds"] = stage("solve");
  figures["newton_iterations"] = total_newton;
  figures["active_set_change_iterations"] = total_changes;
  figures["seconds_per_step_list"] = io::Json::array_of(seconds);
  figures["newton_iterations_per_step"] = io::Json::array_of(newton);
  figures["active_set_change_iterations_per_step"] = io::Json::array_of(changes);
  figures["active_set_node_changes_per_step"] = io::Json::array_of(node_changes);
  figures["active_nodes_per_step"] = io::Json::array_of(active);
  figures["max_penetration"] = *std::max_element(penetration.begin(), penetration.end());
  figures["gap_tolerance"] = status.gap_tolerance;
  figures["contact_total_force"] = status.total_force;
  std::error_code ignored;
  MPI_Barrier(comm);
  if (context.rank() == 0) std::filesystem::remove_all(directory, ignored);
  return figures;
}

}  // namespace coapt::bench
