// SolidModel as the coupled problems use it, on 1, 2 and 3 ranks: the extra nodal force
// enters the residual like a load, a Newmark step repeated from the committed state (a
// coupling iteration) gives the same trial state, a body whose inertia density is offset
// to zero (an immersed solid as dense as the fluid) steps quasi-statically, the iteration
// inertia (set_iteration_density) cancels at the fixed point of the iteration that loads the
// solid with its iteration_force(), and a driver's options (SolidModelOptions) make a case
// without time keys dynamic and refine its mesh; a uniform immersed pressure loads it as the
// follower pressure on its boundary; the volume its whole boundary sweeps over a step is the
// change of its volume; a step solved from the last iterate's state reaches the same state in
// fewer Newton iterations.

#include <gtest/gtest.h>
#include <petscvec.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "coapt/core/context.hpp"
#include "coapt/core/error.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/mesh/mesh.hpp"
#include "coapt/run/run_output.hpp"
#include "coapt/solid/solid_model.hpp"

namespace {

using coapt::OwnedVec;
using coapt::config::Document;
using coapt::solid::SolidModel;

const MPI_Comm kWorld = MPI_COMM_WORLD;

/// A clamped strip [0, 1] × [0, 0.1] of linear elastic (or the given) material, static or
/// Newmark.
std::string strip_case(const std::string& extra,
                       const std::string& material =
                           "{model: linear_elastic, young_modulus: 1.0e6, poisson_ratio: 0.3}") {
  return R"(problem: solid
mesh: {type: rectangle, lower: [0, 0], upper: [1, 0.1], cells: [10, 2]}
bodies:
  - name: strip
    density: 1000
    material: )" +
         material + R"(
dirichlet:
  - boundary: left
newton: {relative_tolerance: 1.0e-12}
output: {vtk: false}
)" + extra;
}

/// A run folder for the model's timers (one per test, removed afterwards).
struct Output {
  explicit Output(const std::string& name)
      : directory(std::filesystem::temp_directory_path() / ("coapt_test_solid_model_" + name)),
        output(kWorld, directory, "", "test", "test") {}
  ~Output() {
    int rank = 0;
    MPI_Comm_rank(kWorld, &rank);
    MPI_Barrier(kWorld);
    if (rank == 0) std::filesystem::remove_all(directory);
  }
  std::filesystem::path directory;
  coapt::run::RunOutput output;
};

double max_difference(Vec a, Vec b) {
  Vec difference = nullptr;
  VecDuplicate(a, &difference);
  VecWAXPY(difference, -1.0, a, b);
  PetscReal norm = 0;
  VecNorm(difference, NORM_INFINITY, &norm);
  VecDestroy(&difference);
  return norm;
}

double max_norm(Vec a) {
  PetscReal norm = 0;
  VecNorm(a, NORM_INFINITY, &norm);
  return norm;
}

TEST(SolidModel, ExtraForceActsLikeTheLoadItStandsFor) {
  Output output("extra_force");
  auto loaded = Document::from_string(strip_case("gravity: [0, -0.5]\n"), "loaded.yaml");
  SolidModel reference(loaded.root(), kWorld);
  reference.solve_static(1.0, output.output, "gravity", false);

  auto unloaded = Document::from_string(strip_case(""), "unloaded.yaml");
  SolidModel solid(unloaded.root(), kWorld);
  const auto& mesh = solid.mesh();
  // The nodal loads of gravity, ρ g |T|/3 per vertex of each cell, as an external force.
  OwnedVec force = coapt::fem::create_vertex_vector(mesh, 2);
  coapt::fem::assemble_vector(mesh, 2, force, [&](int c, double* element) {
    const double share = 1000 * 0.5 * std::abs(coapt::mesh::cell_signed_measure(mesh, c)) / 3;
    for (int a = 0; a < 3; ++a) {
      element[2 * a] = 0.0;
      element[2 * a + 1] = -share;
    }
  });
  solid.set_external_force(force);
  solid.solve_static(1.0, output.output, "extra force", false);
  const double scale = max_norm(reference.displacement());
  EXPECT_GT(scale, 1e-4);
  EXPECT_LT(max_difference(reference.displacement(), solid.displacement()), 1e-10 * scale);
}

// The fluid's pressure an immersed solid carries (set_immersed_pressure), −∫ p div_x w over
// the current configuration: for a uniform p it is, cell by cell, the follower pressure −p n
// on the boundary, so the strip loaded by it must deform as the strip with `pressures:` on
// its free sides (the clamped side's load goes into the reaction). The load is large (5 % of
// E, a visible geometric nonlinearity) and Newton converges as fast with it as with the
// follower pressure (the tangent is exact), and a zero field changes nothing.
TEST(SolidModel, UniformImmersedPressureIsTheFollowerPressureOnItsBoundary) {
  Output output("immersed_pressure");
  constexpr double pressure = 5.0e4;
  const std::string neo_hookean =
      "    material: {model: neo_hookean, young_modulus: 1.0e6, poisson_ratio: 0.3}\n";
  auto with_material = [&](std::string text) {
    const auto at = text.find("    material:");
    const auto end = text.find('\n', at);
    return text.replace(at, end - at + 1, neo_hookean);
  };
  auto loaded =
      Document::from_string(with_material(strip_case("pressures:\n"
                                                     "  - {boundary: right, pressure: 5.0e4}\n"
                                                     "  - {boundary: top, pressure: 5.0e4}\n"
                                                     "  - {boundary: bottom, pressure: 5.0e4}\n")),
                            "follower.yaml");
  SolidModel reference(loaded.root(), kWorld);
  const auto follower = reference.solve_static(1.0, output.output, "follower", false);

  auto unloaded = Document::from_string(with_material(strip_case("")), "immersed.yaml");
  SolidModel solid(unloaded.root(), kWorld);
  OwnedVec field = coapt::fem::create_vertex_vector(solid.mesh(), 1);
  VecSet(field, 0.0);
  coapt::fem::update_ghosts(field);
  solid.set_immersed_pressure(field);
  solid.solve_static(1.0, output.output, "zero", false);
  EXPECT_EQ(max_norm(solid.displacement()), 0.0);

  VecSet(field, pressure);
  coapt::fem::update_ghosts(field);
  const auto immersed = solid.solve_static(1.0, output.output, "immersed", false);
  const double scale = max_norm(reference.displacement());
  EXPECT_GT(scale, 1e-3);  // the strip shortens by about (1 + ν)(1 − 2ν) p/E
  EXPECT_LT(max_difference(reference.displacement(), solid.displacement()), 1e-9 * scale);
  EXPECT_LE(immersed.newton_iterations, follower.newton_iterations + 1);
}

TEST(SolidModel, RepeatedStepFromTheCommittedStateIsIdentical) {
  Output output("repeat");
  auto document = Document::from_string(
      strip_case("time: {scheme: newmark, step: 0.01, end_time: 1, initial_velocity: [0, 0.05]}\n"),
      "dynamic.yaml");
  SolidModel solid(document.root(), kWorld);
  solid.initialize_dynamics(output.output);
  solid.step(0.01, 0.01, output.output);
  OwnedVec first = coapt::fem::create_vertex_vector(solid.mesh(), 2);
  VecCopy(solid.displacement(), first);
  EXPECT_GT(max_norm(first), 1e-5);

  // A coupling iteration: another force, then back to none; the step is taken again.
  OwnedVec force = coapt::fem::create_vertex_vector(solid.mesh(), 2);
  VecSet(force, 1e-3);
  solid.set_external_force(force);
  solid.restore();
  solid.step(0.01, 0.01, output.output);
  EXPECT_GT(max_difference(first, solid.displacement()), 1e-8);
  solid.set_external_force(nullptr);
  solid.restore();
  solid.step(0.01, 0.01, output.output);
  EXPECT_EQ(max_difference(first, solid.displacement()), 0.0);

  // After commit() the next step starts from the new state.
  solid.commit();
  solid.step(0.02, 0.01, output.output);
  EXPECT_GT(max_difference(first, solid.displacement()), 1e-6);
}

// A coupling iteration's solve from the last iterate's state (step(..., from_current)): a
// neo-Hookean strip under a load that changes a little between two solves of the same step
// reaches the state the solve from the predictor reaches, to the Newton tolerance, in fewer
// iterations; where the last state is not nearer than the predictor it starts from the
// predictor and repeats the plain step exactly.
TEST(SolidModel, StepFromTheLastIterateReachesTheSameStateInFewerIterations) {
  for (const bool stabilized : {false, true}) {
    SCOPED_TRACE(stabilized ? "contact_stabilized_newmark" : "newmark");
    Output output(stabilized ? "warm_start_csn" : "warm_start");
    auto document = Document::from_string(
        strip_case("gravity: [0, -50]\ntime: {scheme: newmark, step: 0.05, end_time: 1}\n",
                   "{model: neo_hookean, young_modulus: 1.0e5, poisson_ratio: 0.3}"),
        "warm.yaml");
    SolidModel solid(document.root(), kWorld);
    solid.set_contact_stabilized(stabilized);
    solid.initialize_dynamics(output.output);
    OwnedVec force = coapt::fem::create_vertex_vector(solid.mesh(), 2);
    VecSet(force, 0.0);
    solid.set_external_force(force);
    solid.step(0.05, 0.05, output.output);  // the first coupling iteration
    // the next iterate's load: 0.5 % more weight (ρ g |strip|), spread over the 33 vertices
    const double extra = -0.005 * 50 * 1000 * 0.1 / 33;
    VecSet(force, extra);
    solid.restore();
    const auto cold = solid.step(0.05, 0.05, output.output);
    OwnedVec reference = coapt::fem::create_vertex_vector(solid.mesh(), 2);
    VecCopy(solid.displacement(), reference);
    const double scale = max_norm(reference);
    EXPECT_GT(scale, 1e-2);
    EXPECT_GE(cold.newton_iterations, 3);

    VecSet(force, 0.0);
    solid.restore();
    solid.step(0.05, 0.05, output.output);  // the first iterate again
    VecSet(force, extra);
    const auto warm = solid.step(0.05, 0.05, output.output, true);
    EXPECT_LT(max_difference(reference, solid.displacement()), 1e-8 * scale);
    EXPECT_LT(warm.newton_iterations, cold.newton_iterations);

    // from the committed state (restore()): the same state; with the contact-stabilized
    // scheme the predictor from rest is the committed state, not nearer, so the predictor is
    // kept and the plain step repeats exactly
    solid.restore();
    const auto restored = solid.step(0.05, 0.05, output.output, true);
    EXPECT_LT(max_difference(reference, solid.displacement()), 1e-8 * scale);
    if (stabilized) {
      EXPECT_EQ(max_difference(reference, solid.displacement()), 0.0);
      EXPECT_EQ(restored.newton_iterations, cold.newton_iterations);
    }
  }
}

// newton.reuse_factorisation: a time step's first factorisation serves the step's later
// Newton and coupling iterations under GMRES. A neo-Hookean strip falling under gravity (up
// to 13 Newton iterations a step), each step solved twice with a slightly different extra
// load (two coupling iterations), reaches the states of the plain direct solves to the
// Newton tolerance with fewer than half the factorisations. Each step's first solve factors
// afresh, so a step repeated after restore() repeats bit for bit (what a restart needs). A
// static solid refuses the key.
TEST(SolidModel, ReusedFactorisationGivesTheSameStatesWithFewerFactorisations) {
  const std::string material = "{model: neo_hookean, young_modulus: 1.0e5, poisson_ratio: 0.3}";
  const std::string time = "gravity: [0, -50]\ntime: {scheme: newmark, step: 0.05, end_time: 1}\n";
  auto with_reuse = [&](const std::string& text) {
    const std::string plain = "newton: {relative_tolerance: 1.0e-12}";
    std::string changed = text;
    changed.replace(changed.find(plain), plain.size(),
                    "newton: {relative_tolerance: 1.0e-12, reuse_factorisation: 10}");
    return changed;
  };
  Output output("reuse");
  auto plain_document = Document::from_string(strip_case(time, material), "plain.yaml");
  auto reuse_document = Document::from_string(with_reuse(strip_case(time, material)), "reuse.yaml");
  SolidModel plain(plain_document.root(), kWorld), reused(reuse_document.root(), kWorld);
  plain.initialize_dynamics(output.output);
  reused.initialize_dynamics(output.output);
  OwnedVec force = coapt::fem::create_vertex_vector(plain.mesh(), 2);
  OwnedVec first = coapt::fem::create_vertex_vector(plain.mesh(), 2);
  plain.set_external_force(force);
  reused.set_external_force(force);
  const double extra = -0.005 * 50 * 1000 * 0.1 / 33;  // 0.5 % of the weight per vertex
  int newton = 0, factorisations = 0;
  for (int step = 1; step <= 5; ++step) {
    SCOPED_TRACE(step);
    const double t = 0.05 * step;
    for (const int iteration : {1, 2}) {
      VecSet(force, iteration == 1 ? 0.0 : extra);
      plain.step(t, 0.05, output.output);
      const auto report = reused.step(t, 0.05, output.output);
      const double scale = max_norm(plain.displacement());
      EXPECT_GT(scale, 1e-4);
      EXPECT_LT(max_difference(plain.displacement(), reused.displacement()), 1e-8 * scale);
      EXPECT_LT(max_difference(plain.velocity(), reused.velocity()),
                1e-6 * max_norm(plain.velocity()));
      EXPECT_GE(report.factorisations, iteration == 1 ? 1 : 0);
      EXPECT_LT(report.factorisations, report.newton_iterations);
      newton += report.newton_iterations;
      factorisations += report.factorisations;
      if (iteration == 1) VecCopy(reused.displacement(), first);
    }
    // the first iteration again from the committed state: the same bits
    reused.restore();
    VecSet(force, 0.0);
    reused.step(t, 0.05, output.output);
    EXPECT_EQ(max_difference(first, reused.displacement()), 0.0);
    VecSet(force, extra);
    reused.step(t, 0.05, output.output);
    plain.commit();
    reused.commit();
  }
  EXPECT_LT(2 * factorisations, newton);

  auto static_document = Document::from_string(with_reuse(strip_case("")), "static.yaml");
  try {
    SolidModel refused(static_document.root(), kWorld);
    ADD_FAILURE() << "a static solid took newton.reuse_factorisation";
  } catch (const coapt::InputError& error) {
    EXPECT_NE(std::string(error.what()).find("reuse_factorisation"), std::string::npos)
        << error.what();
  }
}

// The volume the boundary sweeps over a step (surface_swept_volume, what the valve's leak
// takes from the flow through the inlet) is, summed over the whole boundary, exactly the
// change of the body's volume, in 2D and 3D, for a step with a large, non-uniform motion (a
// neo-Hookean strip pulled down by gravity and stretched by its initial velocity); a clamped
// side sweeps nothing and an unknown group is an input error.
TEST(SolidModel, SweptVolumeOfTheWholeBoundaryIsTheChangeOfVolume) {
  Output output("swept");
  for (const int dim : {2, 3}) {
    const std::string mesh =
        dim == 2 ? "mesh: {type: rectangle, lower: [0, 0], upper: [1, 0.1], cells: [10, 2]}\n"
                 : "mesh: {type: box, lower: [0, 0, 0], upper: [1, 0.1, 0.1], cells: [6, 2, 2]}\n";
    const std::string text =
        "problem: solid\n" + mesh +
        "bodies:\n"
        "  - name: strip\n"
        "    density: 1000\n"
        "    material: {model: neo_hookean, young_modulus: 1.0e5, poisson_ratio: 0.3}\n"
        "dirichlet:\n"
        "  - boundary: left\n"
        "newton: {relative_tolerance: 1.0e-12}\n"
        "output: {vtk: false}\n" +
        (dim == 2 ? "gravity: [0, -50]\n" : "gravity: [0, -50, 20]\n") +
        "time: {scheme: newmark, step: 0.05, end_time: 1, initial_velocity: " +
        (dim == 2 ? "[0.5, 0]" : "[0.5, 0, 0]") + "}\n";
    auto document = Document::from_string(text, "swept.yaml");
    SolidModel solid(document.root(), kWorld);
    solid.initialize_dynamics(output.output);
    const std::vector<std::string> sides =
        dim == 2 ? std::vector<std::string>{"left", "right", "bottom", "top"}
                 : std::vector<std::string>{"left", "right", "front", "back", "bottom", "top"};
    double before = solid.volume();
    for (int step = 1; step <= 2; ++step) {
      solid.step(0.05 * step, 0.05, output.output);
      double swept = 0;
      for (const auto& side : sides) swept += solid.surface_swept_volume(side);
      const double change = solid.volume() - before;
      EXPECT_GT(std::abs(change), 1e-4 * before) << dim << "D, step " << step;
      EXPECT_LT(std::abs(swept - change), 1e-12 * before) << dim << "D, step " << step;
      EXPECT_EQ(solid.surface_swept_volume("left"), 0.0);  // clamped
      solid.commit();
      before = solid.volume();
    }
  }
  auto document = Document::from_string(strip_case(""), "strip.yaml");
  SolidModel solid(document.root(), kWorld);
  EXPECT_THROW(solid.surface_swept_volume("no_such_group"), coapt::InputError);
}

TEST(SolidModel, ZeroInertiaDensityStepsQuasiStatically) {
  Output output("offset");
  auto dynamic = Document::from_string(
      strip_case("gravity: [0, -0.5]\ntime: {scheme: newmark, step: 0.01, end_time: 1}\n"),
      "dynamic.yaml");
  SolidModel solid(dynamic.root(), kWorld);
  solid.set_density_offset(1000);
  solid.initialize_dynamics(output.output);
  solid.step(0.01, 0.01, output.output);
  EXPECT_EQ(solid.kinetic_energy(), 0.0);

  auto quasi_static = Document::from_string(strip_case("gravity: [0, -0.5]\n"), "static.yaml");
  SolidModel reference(quasi_static.root(), kWorld);
  reference.solve_static(1.0, output.output, "static", false);
  const double scale = max_norm(reference.displacement());
  EXPECT_LT(max_difference(reference.displacement(), solid.displacement()), 1e-10 * scale);

  EXPECT_THROW(solid.set_density_offset(1001), coapt::InputError);
}

TEST(SolidModel, IterationInertiaCancelsAtTheFixedPointOfItsIteration) {
  // The coupling's use (fsci_problem.cpp): the load g is iterated as g ← f + iteration_force()
  // (here f = 0, gravity being the case's own load) and the solid committed with g less the
  // last iteration force. Two steps of each scheme; the density 0.1 kg/m³ makes the iteration
  // contract quickly on this strip (the term's effect does not depend on its size).
  for (const bool stabilized : {false, true}) {
    SCOPED_TRACE(stabilized ? "contact_stabilized_newmark" : "newmark");
    Output output(stabilized ? "iteration_inertia_csn" : "iteration_inertia");
    const std::string keys =
        "gravity: [0, -0.5]\ntime: {scheme: newmark, step: 0.01, end_time: 1, "
        "initial_velocity: [0, 0.05]}\n";
    auto document = Document::from_string(strip_case(keys), "dynamic.yaml");
    SolidModel plain(document.root(), kWorld), iterated(document.root(), kWorld);
    for (auto* model : {&plain, &iterated}) {
      model->set_density_offset(900);
      model->set_contact_stabilized(stabilized);
    }
    iterated.set_iteration_density(0.1);
    plain.initialize_dynamics(output.output);
    iterated.initialize_dynamics(output.output);
    OwnedVec load = coapt::fem::create_vertex_vector(iterated.mesh(), 2);
    OwnedVec force = coapt::fem::create_vertex_vector(iterated.mesh(), 2);
    VecSet(load, 0.0);
    iterated.set_external_force(load);
    for (int n = 1; n <= 2; ++n) {
      const double time = 0.01 * n;
      plain.step(time, 0.01, output.output);
      const double scale = max_norm(plain.displacement());
      double change = 0;
      int iterations = 0;
      for (iterations = 1; iterations <= 100; ++iterations) {
        iterated.step(time, 0.01, output.output);
        iterated.iteration_force(force);
        change = max_difference(force, load);
        VecCopy(force, load);
        if (iterations == 1 && n == 1) {
          // the first iterate is not the plain step: the term acts
          EXPECT_GT(max_difference(plain.displacement(), iterated.displacement()), 1e-6 * scale);
        }
        if (change < 1e-13) break;
      }
      EXPECT_LT(change, 1e-13) << iterations << " iterations";
      EXPECT_LT(max_difference(plain.displacement(), iterated.displacement()), 1e-10 * scale);
      EXPECT_LT(max_difference(plain.velocity(), iterated.velocity()),
                1e-8 * max_norm(plain.velocity()));
      VecAXPY(load, -1.0, force);  // committed with g − iteration_force = 0
      plain.commit();
      iterated.commit();
    }
  }
}

TEST(SolidModel, DriverOptionsMakeItDynamicAndRefineItsMesh) {
  // The immersed coupling's solid has no `time:` keys: driver_dynamic makes it step as the
  // same case with time.scheme newmark does; extra_mesh_levels refines its mesh.
  Output output("driver");
  auto own = Document::from_string(
      strip_case("gravity: [0, -0.5]\ntime: {scheme: newmark, step: 0.01, end_time: 1}\n"),
      "own.yaml");
  auto driven = Document::from_string(strip_case("gravity: [0, -0.5]\n"), "driven.yaml");
  SolidModel reference(own.root(), kWorld);
  SolidModel solid(driven.root(), kWorld, {0, "mesh.level", true});
  EXPECT_TRUE(solid.parameters().time.dynamic);
  for (auto* model : {&reference, &solid}) {
    model->initialize_dynamics(output.output);
    model->step(0.01, 0.01, output.output);
  }
  const double scale = max_norm(reference.displacement());
  EXPECT_GT(scale, 1e-6);
  EXPECT_LT(max_difference(reference.displacement(), solid.displacement()), 1e-12 * scale);

  SolidModel refined(driven.root(), kWorld, {1, "mesh.level", false});
  EXPECT_FALSE(refined.parameters().time.dynamic);
  EXPECT_EQ(refined.mesh().n_global_cells, 4 * solid.mesh().n_global_cells);
}

}  // namespace
