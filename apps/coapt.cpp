// coapt — fluid–structure–contact interaction by an immersed domain method.
//
//   coapt run CASE.yaml [--output DIR] [--restart DIR] [--set key.path=value ...]
//       [-- PETSc options]
//   coapt check CASE.yaml [--set key.path=value ...]
//   coapt mesh FILE.msh
//   coapt keys CASE.yaml        (the keys the case understands, with units and defaults)
//
// Exit status: 0 success, 1 the run failed (solver, divergence), 2 bad input, 3 internal error.

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"
#include "coapt/mesh/gmsh_reader.hpp"
#include "coapt/mesh/quality.hpp"
#include "coapt/run/problem.hpp"
#include "coapt/run/run_output.hpp"

namespace {

constexpr int kExitFailed = 1;
constexpr int kExitInput = 2;
constexpr int kExitInternal = 3;

struct Options {
  std::string case_file;
  std::string output;
  std::string restart;
  std::vector<std::string> overrides;
  std::string mesh_file;
  bool strict_options = false;
  std::string log_level = "info";
};

coapt::config::Document load_case(const Options& options) {
  auto document = coapt::config::Document::from_file(options.case_file);
  for (const auto& assignment : options.overrides) document.set(assignment);
  return document;
}

std::string default_output(const std::string& case_file) {
  const auto path = std::filesystem::path(case_file);
  const auto parent = path.parent_path().filename().string();
  return (std::filesystem::path("out") /
          ((parent.empty() ? "" : parent + "-") + path.stem().string()))
      .string();
}

std::string command_line(int argc, char** argv) {
  std::string text;
  for (int i = 0; i < argc; ++i) text += (i ? " " : "") + std::string(argv[i]);
  return text;
}

int check(const Options& options, const coapt::Context& context) {
  auto document = load_case(options);
  auto problem = coapt::run::create_problem(document.root(), context.comm());
  document.reject_unknown_keys();
  problem->describe();
  coapt::log::info("{}: the case is valid", options.case_file);
  return 0;
}

int keys(const Options& options, const coapt::Context& context) {
  auto document = load_case(options);
  auto problem = coapt::run::create_problem(document.root(), context.comm());
  document.reject_unknown_keys();
  coapt::log::info("| key | type | default | unit | range | meaning |");
  coapt::log::info("| --- | --- | --- | --- | --- | --- |");
  for (const auto& key : document.keys())
    coapt::log::info("| `{}` | {} | {} | {} | {} | {} |", key.path, key.type,
                     key.type.find("section") != std::string::npos ? ""
                     : key.default_value.empty()                   ? "required"
                                                                   : "`" + key.default_value + "`",
                     key.unit, key.range, key.doc);
  return 0;
}

int mesh(const Options& options, const coapt::Context& context) {
  if (context.rank() != 0) return 0;
  auto whole = coapt::mesh::read_gmsh(options.mesh_file);
  coapt::mesh::orient_cells(whole);
  const auto report = coapt::mesh::check_quality(whole);
  coapt::log::info("{}: {}D, {} vertices, {} cells, {} tagged boundary facets", options.mesh_file,
                   whole.dim, whole.n_vertices(), whole.n_cells(), whole.n_facets());
  std::vector<double> lower(static_cast<std::size_t>(whole.dim), 1e300),
      upper(static_cast<std::size_t>(whole.dim), -1e300);
  for (int v = 0; v < whole.n_vertices(); ++v)
    for (int d = 0; d < whole.dim; ++d) {
      lower[d] = std::min(lower[d], whole.point(v)[d]);
      upper[d] = std::max(upper[d], whole.point(v)[d]);
    }
  coapt::log::info("bounding box: [{}] to [{}] m", fmt::join(lower, ", "), fmt::join(upper, ", "));
  for (const auto& group : whole.groups) {
    long count = 0;
    if (group.dim == whole.dim)
      count = std::count(whole.cell_tags.begin(), whole.cell_tags.end(), group.tag);
    if (group.dim == whole.dim - 1)
      count = std::count(whole.facet_tags.begin(), whole.facet_tags.end(), group.tag);
    coapt::log::info("physical group '{}' (dimension {}, tag {}): {} elements", group.name,
                     group.dim, group.tag, count);
  }
  coapt::log::info(
      "cell measure in [{:.4e}, {:.4e}] (total {:.6e}), shape quality (mean ratio, 1 = regular) in "
      "[{:.4f}, {:.4f}]",
      report.min_measure, report.max_measure, report.total_measure, report.min_shape,
      report.max_shape);
  coapt::log::info("{} inverted and {} degenerate cells", report.inverted.size(),
                   report.degenerate.size());
  coapt::mesh::require_valid(whole, report);
  return 0;
}

int run(const Options& options, const coapt::Context& context, const std::string& command) {
  const std::string directory =
      options.output.empty() ? default_output(options.case_file) : options.output;
  std::unique_ptr<coapt::run::RunOutput> output;
  try {
    auto document = load_case(options);
    auto problem = coapt::run::create_problem(document.root(), context.comm());
    document.reject_unknown_keys();
    std::unique_ptr<coapt::run::CheckpointReader> checkpoint;
    if (!options.restart.empty())
      checkpoint = std::make_unique<coapt::run::CheckpointReader>(context.comm(), options.restart);
    output = std::make_unique<coapt::run::RunOutput>(
        context.comm(), directory, document.resolved_yaml(), options.case_file, command);
    coapt::log::info("coapt {} on {} rank(s): {} -> {}", COAPT_VERSION, context.size(),
                     options.case_file, directory);
    if (checkpoint) {
      coapt::log::info("restarting from {}", checkpoint->directory().string());
      output->summary()["restarted_from"] = checkpoint->directory().string();
      problem->restart_from(*checkpoint);
    }
    problem->run(*output);
    const auto unused = coapt::Context::unused_petsc_options();
    if (!unused.empty()) {
      coapt::io::Json list = coapt::io::Json::array();
      for (const auto& option : unused) list.push_back(option);
      output->summary()["unused_petsc_options"] = list;
      const std::string message =
          fmt::format("PETSc option(s) given but never used (misspelt or not for this case): {}",
                      fmt::join(unused, ", "));
      if (options.strict_options) throw coapt::InputError(message);
      coapt::log::warn("warning: {}", message);
    }
    output->complete();
    coapt::log::info("done: {}/summary.json", directory);
    return 0;
  } catch (const coapt::Error& e) {
    // Input errors before the folder exists leave no folder; later failures mark it failed.
    if (!output && !dynamic_cast<const coapt::InputError*>(&e)) {
      try {
        output = std::make_unique<coapt::run::RunOutput>(context.comm(), directory, "",
                                                         options.case_file, command);
      } catch (const coapt::Error&) {
      }
    }
    if (output && !output->finished()) output->fail(e.what());
    throw;
  }
}

}  // namespace

int main(int argc, char** argv) {
  int n_ours = argc;
  const auto petsc_arguments = coapt::split_petsc_arguments(argc, argv, n_ours);

  Options options;
  CLI::App app{"coapt: fluid-structure-contact interaction by an immersed domain method"};
  app.set_version_flag("--version", std::string("coapt ") + COAPT_VERSION);
  app.require_subcommand(1);
  app.add_option("--log-level", options.log_level, "debug, info, warn or error")
      ->check(CLI::IsMember({"debug", "info", "warn", "error"}));
  auto* run_command = app.add_subcommand(
      "run", "run a case: coapt run CASE.yaml [--output DIR] [--set k=v ...] [-- PETSc options]");
  run_command->add_option("case", options.case_file, "the case file (YAML)")->required();
  run_command->add_option("--output,-o", options.output,
                          "output folder (default: out/<case folder>-<case name>)");
  run_command->add_option("--set", options.overrides,
                          "override a key of the case: key.path=value (repeatable)");
  run_command->add_option("--restart", options.restart,
                          "continue from the last checkpoint of an earlier run folder DIR "
                          "(the case's output.checkpoint_interval writes them)");
  run_command->add_flag("--strict-options", options.strict_options,
                        "fail when a PETSc option is never used");
  auto* check_command =
      app.add_subcommand("check", "validate a case and load its meshes; solves nothing");
  check_command->add_option("case", options.case_file, "the case file (YAML)")->required();
  check_command->add_option("--set", options.overrides,
                            "override a key of the case: key.path=value (repeatable)");
  auto* keys_command =
      app.add_subcommand("keys", "list the keys a case understands, with units and defaults");
  keys_command->add_option("case", options.case_file, "the case file (YAML)")->required();
  keys_command->add_option("--set", options.overrides,
                           "override a key of the case: key.path=value (repeatable)");
  auto* mesh_command =
      app.add_subcommand("mesh", "statistics, physical groups and quality of a Gmsh mesh");
  mesh_command->add_option("file", options.mesh_file, "the mesh (.msh, version 2 or 4)")
      ->required();
  app.footer("PETSc options (solvers: -poisson_ksp_type, -fluid_pc_type, ...) go after '--'.");

  try {
    app.parse(n_ours, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  int status = 0;
  try {
    coapt::Context context(petsc_arguments);
    coapt::log::initialize(context.rank());
    coapt::log::set_level(options.log_level);
    try {
      if (*run_command)
        status = run(options, context, command_line(argc, argv));
      else if (*check_command)
        status = check(options, context);
      else if (*keys_command)
        status = keys(options, context);
      else if (*mesh_command)
        status = mesh(options, context);
    } catch (const coapt::InputError& e) {
      if (context.rank() == 0) std::cerr << "coapt: error: " << e.what() << std::endl;
      status = kExitInput;
    } catch (const coapt::InternalError& e) {
      if (context.rank() == 0)
        std::cerr << "coapt: internal error (please report): " << e.what() << std::endl;
      status = kExitInternal;
    } catch (const coapt::Error& e) {
      if (context.rank() == 0) std::cerr << "coapt: run failed: " << e.what() << std::endl;
      status = kExitFailed;
    } catch (const std::exception& e) {
      std::cerr << "coapt: internal error (please report): " << e.what() << std::endl;
      status = kExitInternal;
    }
    int worst = status;
    MPI_Allreduce(&status, &worst, 1, MPI_INT, MPI_MAX, context.comm());
    status = worst;
  } catch (const coapt::Error& e) {
    std::cerr << "coapt: error: " << e.what() << std::endl;
    return kExitInternal;
  }
  return status;
}
