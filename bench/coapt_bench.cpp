// coapt-bench: coapt's benchmark program, one sub-command per measurement.
//
//   mpirun -np 2 coapt-bench assembly --n 64
//   mpirun -np 2 coapt-bench fluid --n 12 -- -fluid_pc_type lu
//   mpirun -np 2 coapt-bench solid --n 44
//   mpirun -np 2 coapt-bench contact --level 1 --size 4.5e-4
//   mpirun -np 2 coapt-bench fsci --case cases/valve2d.yaml --steps 5
//
// Each sub-command prints what it does and ends with one line holding a JSON object of the
// figures (rates carry their unit in the key) and the peak memory per rank (peak_rss_mb).
// Results go in bench/RESULTS.md with the date, the machine and the command.

#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <iostream>
#include <string>

#include "bench_common.hpp"
#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"

int main(int argc, char** argv) {
  int n_ours = argc;
  const auto petsc_arguments = coapt::split_petsc_arguments(argc, argv, n_ours);
  CLI::App app{"coapt-bench: coapt's benchmarks"};
  app.require_subcommand(1);
  coapt::bench::AssemblyOptions assembly;
  auto* assembly_command = app.add_subcommand(
      "assembly", "P1 Laplacian and elasticity assembly on the unit cube (n^3 * 6 tets)");
  assembly_command->add_option("--n", assembly.n, "cells per direction")->check(CLI::Range(1, 400));
  assembly_command
      ->add_option("--repeat", assembly.repeat, "re-assemblies timed (the mean is reported)")
      ->check(CLI::Range(1, 1000));
  coapt::bench::TransferBenchOptions transfer;
  auto* transfer_command = app.add_subcommand(
      "transfer", "variational transfer operators: unit cube (n^3 * 6 tets) against a master");
  transfer_command->add_option("--n", transfer.n, "cells per direction")->check(CLI::Range(1, 400));
  transfer_command->add_option("--case", transfer.case_name, "jitter or rotated")
      ->check(CLI::IsMember({"jitter", "rotated"}));
  coapt::bench::FluidBenchOptions fluid;
  auto* fluid_command = app.add_subcommand(
      "fluid",
      "stabilised Navier-Stokes on a 3D channel (4n x n x n cubes * 6 tets): assembly, one "
      "steady Newton solve");
  fluid_command->add_option("--n", fluid.n, "cells across the channel")->check(CLI::Range(1, 200));
  fluid_command->add_option("--repeat", fluid.repeat, "assemblies timed (the mean is reported)")
      ->check(CLI::Range(1, 1000));
  coapt::bench::SolidBenchOptions solid;
  auto* solid_command = app.add_subcommand(
      "solid",
      "nearly incompressible Neo-Hookean solid on the unit cube (n^3 * 6 tets): time per Newton "
      "iteration, assembly and solve");
  solid_command->add_option("--n", solid.n, "cells per direction")->check(CLI::Range(1, 200));
  solid_command->add_option("--formulation", solid.formulation, "displacement or mixed")
      ->check(CLI::IsMember({"displacement", "mixed"}));
  coapt::bench::ContactBenchOptions contact;
  auto* contact_command = app.add_subcommand(
      "contact",
      "two plates pressed and slid with frictionless mortar contact (cases/contact/"
      "plates3d.yaml): time per load step, Newton iterations, active-set changes");
  contact_command->add_option("--case", contact.case_file, "the plates case file");
  contact_command->add_option("--level", contact.level, "mesh.level")->check(CLI::Range(0, 6));
  contact_command->add_option("--size", contact.size, "mesh.size [m] (0: the case's)")
      ->check(CLI::Range(0.0, 1.0));
  contact_command
      ->add_option("--steps", contact.steps, "run only the first this many load steps (0: all)")
      ->check(CLI::Range(0, 100000));
  coapt::bench::FsciBenchOptions fsci;
  auto* fsci_command = app.add_subcommand(
      "fsci",
      "a transient coupled run (problem: fsci, default cases/valve2d.yaml) for some steps: wall "
      "time per stage (solid, contact, transfer, fluid, coupling)");
  fsci_command->add_option("--case", fsci.case_file, "the fsci case file");
  fsci_command->add_option("--level", fsci.level, "mesh.level")->check(CLI::Range(0, 6));
  fsci_command->add_option("--steps", fsci.steps, "time steps")->check(CLI::Range(1, 100000));
  fsci_command->add_option("--output", fsci.output, "the run folder");
  fsci_command->add_option("--set", fsci.assignments, "override a case key (key=value)");
  try {
    app.parse(n_ours, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    coapt::Context context(petsc_arguments);
    coapt::log::initialize(context.rank());
    coapt::io::Json figures;
    if (*assembly_command) figures = coapt::bench::assembly(context, assembly);
    if (*transfer_command) figures = coapt::bench::transfer(context, transfer);
    if (*fluid_command) figures = coapt::bench::fluid(context, fluid);
    if (*solid_command) figures = coapt::bench::solid(context, solid);
    if (*contact_command) figures = coapt::bench::contact(context, contact);
    if (*fsci_command) figures = coapt::bench::fsci(context, fsci);
    figures["peak_rss_mb"] = coapt::bench::peak_rss_mb(context.comm());
    if (context.rank() == 0) std::cout << figures.dump(-1) << std::endl;
  } catch (const coapt::Error& e) {
    std::cerr << "coapt-bench: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
