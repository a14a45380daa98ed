// The immersed velocity constraint (coupling::ImmersedConstraint) and the reusable fluid
// (fluid::FluidModel) on 1, 2 and 3 ranks, on a channel [0, 2] × [0, 1] with a non-matching
// unstructured solid square [0.6, 1.0] × [0.3, 0.7] immersed in it:
//  - T = D⁻¹B reproduces a linear solid velocity at every constrained fluid node to
//    round-off (biorthogonality on wholly covered supports), and a uniform one;
//  - after a Navier–Stokes solve with the body held at rest, the force on the solid Bᵀλ
//    (λ = reaction / D) sums to the total constraint reaction to round-off, the drag is
//    positive, and the constrained velocities are exactly zero;
//  - a solid clamped to a wall leaves the wall's vertices to their no-slip condition;
//  - two solids that together cover the square (coupling::ConstraintGroup) are constrained as
//    the square: the same vertices, a linear velocity exactly, the same total force;
//  - FluidModel::boundary_force read after commit_step (and after a dropped trial) is the force
//    of the committed step, with that step's own BDF history;
//  - FluidModel::restore_step repeats a step from the same history bit for bit (state and
//    reactions), as the coupling iterations and step retries need.
//  - partial coverage (ImmersedConstraint's partial_from): the partly covered nodes' weights
//    follow their coverage and change continuously as the solid moves, their targets are
//    averages of the solid's velocity, the force balance holds with them, and their blocking
//    lies between the two covered-node rules they interpolate; a penalty of a very large
//    weight gives the constraint's velocities and reactions (NavierStokes::set_velocity_penalty);
//    the penalty's stiffness κ follows 1/Δt by default and is the same for every Δt with a
//    time scale τ (coupling.partial_time_scale).
//  - fluid.covered_continuity_factor κ: the leak through a band held at rest across a channel
//    is the band's PSPG flux, κ times the unscaled one (its resistance affine in 1/κ), with
//    the band's pressure between the ends'; only in the cells the solids cover wholly
//    (fluid.covered_continuity_coverage).

#include <gtest/gtest.h>
#include <petscvec.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "coapt/core/config.hpp"
#include "coapt/core/context.hpp"
#include "coapt/coupling/constraint_group.hpp"
#include "coapt/coupling/immersed_constraint.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fluid/fluid_model.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"

namespace {

using coapt::coupling::ConstraintGroup;
using coapt::coupling::ImmersedConstraint;
using coapt::fluid::FluidCase;
using coapt::fluid::FluidModel;
using coapt::mesh::Mesh;

const MPI_Comm kWorld = MPI_COMM_WORLD;

constexpr const char* kCase = R"(
mesh: {type: rectangle, lower: [0, 0], upper: [2, 1], cells: [40, 20]}
fluid: {density: 1.0, viscosity: 0.01}
boundary:
  - {group: bottom, type: no_slip}
  - {group: top, type: no_slip}
  - {group: left, type: velocity, profile: parabolic, value: [1.0, 0.0], from: [0, 0], to: [0, 1]}
  - {group: right, type: outflow}
)";

FluidCase read_case() {
  auto document = coapt::config::Document::from_string(kCase, "channel.yaml");
  const auto root = document.root();
  return FluidCase::read(root, root.section("fluid"));
}

Mesh solid_square() {
  Mesh whole;
  if (coapt::rank_of(kWorld) == 0)
    whole = coapt::mesh::unstructured_rectangle(0.6, 0.3, 1.0, 0.7, 0.045);
  return coapt::mesh::distribute(whole, kWorld, coapt::mesh::Partitioner::blocks);
}

/// A solid vertex vector with v(x) = (a + b x + c y, d − c x) (dim 2 components).
coapt::OwnedVec linear_velocity(const ImmersedConstraint& constraint, const Mesh& solid) {
  auto vector = constraint.create_solid_vector();
  PetscScalar* values = nullptr;
  VecGetArray(vector, &values);
  for (int v = 0; v < solid.n_owned_vertices; ++v) {
    const double x = solid.point(v)[0], y = solid.point(v)[1];
    values[2 * v] = 0.3 + 1.5 * x - 0.7 * y;
    values[2 * v + 1] = -0.2 + 0.7 * x;
  }
  VecRestoreArray(vector, &values);
  return vector;
}

double sum_all(double value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_SUM, kWorld);
  return value;
}

TEST(CouplingConstraint, TransferReproducesLinearVelocities) {
  FluidModel fluid(read_case(), kWorld);
  const Mesh solid = solid_square();
  ImmersedConstraint constraint(fluid.mesh(), solid, {});
  // Fluid vertices with a whole support in the square: x ∈ [0.65, 0.95], y ∈ [0.35, 0.65] on
  // the 0.05 grid, 7 × 7 of them.
  EXPECT_EQ(constraint.n_constrained(), 49);
  const auto velocity = linear_velocity(constraint, solid);
  const auto transferred = constraint.transfer_velocity(velocity);
  const auto uniform = constraint.transfer_uniform_velocity({0.25, -1.5});
  double error = 0, uniform_error = 0;
  const auto& vertices = constraint.constrained_vertices();
  for (std::size_t q = 0; q < vertices.size(); ++q) {
    const double x = fluid.mesh().point(vertices[q])[0], y = fluid.mesh().point(vertices[q])[1];
    error = std::max({error, std::abs(transferred[2 * q] - (0.3 + 1.5 * x - 0.7 * y)),
                      std::abs(transferred[2 * q + 1] - (-0.2 + 0.7 * x))});
    uniform_error = std::max(
        {uniform_error, std::abs(uniform[2 * q] - 0.25), std::abs(uniform[2 * q + 1] + 1.5)});
  }
  MPI_Allreduce(MPI_IN_PLACE, &error, 1, MPI_DOUBLE, MPI_MAX, kWorld);
  MPI_Allreduce(MPI_IN_PLACE, &uniform_error, 1, MPI_DOUBLE, MPI_MAX, kWorld);
  EXPECT_LT(error, 1e-12);
  EXPECT_LT(uniform_error, 1e-13);
}

TEST(CouplingConstraint, ForceOnSolidBalancesReactions) {
  FluidModel fluid(read_case(), kWorld);
  const Mesh solid = solid_square();
  ImmersedConstraint constraint(fluid.mesh(), solid, {});
  fluid.start(0.0);
  fluid.set_velocity_constraint(constraint.constrained_vertices(),
                                constraint.transfer_uniform_velocity({0.0, 0.0}));
  fluid.solve_steady("immersed square");
  const auto reactions = fluid.constraint_reactions();
  const auto lambda = constraint.multiplier(reactions);
  auto force = constraint.create_solid_vector();
  constraint.solid_force(lambda, force);
  const auto total = constraint.sum_components(force);
  const auto total_reaction = constraint.sum_constrained(reactions);
  for (int i = 0; i < 2; ++i)
    EXPECT_NEAR(total[i], total_reaction[i], 1e-12 * std::abs(total_reaction[0]))
        << "component " << i;
  EXPECT_GT(total[0], 0.0) << "the flow drags the square downstream";
  // The constrained velocities hold exactly.
  coapt::fem::LocalValues state(fluid.state());
  double held = 0;
  for (const int v : constraint.constrained_vertices())
    held = std::max({held, std::abs(state[3 * static_cast<std::size_t>(v)]),
                     std::abs(state[3 * static_cast<std::size_t>(v) + 1])});
  EXPECT_EQ(held, 0.0);
  if (coapt::rank_of(kWorld) == 0)
    std::printf("immersed square: force (%.10e, %.10e), %d constrained\n", total[0], total[1],
                static_cast<int>(constraint.n_constrained()));
}

TEST(CouplingConstraint, WallVerticesAreLeftToTheirBoundaryCondition) {
  // A square clamped to the bottom wall, [0.6, 1.0] × [−0.2, 0.3]: the wall's fluid vertices
  // under it are covered, but their no-slip condition holds there and their reaction is the
  // wall's, so that the body's force does not count it twice (FluidModel::
  // velocity_condition_vertices, ImmersedConstraint's `fixed`).
  FluidModel fluid(read_case(), kWorld);
  fluid.start(0.0);
  Mesh whole;
  if (coapt::rank_of(kWorld) == 0)
    whole = coapt::mesh::unstructured_rectangle(0.6, -0.2, 1.0, 0.3, 0.045);
  const Mesh solid = coapt::mesh::distribute(whole, kWorld, coapt::mesh::Partitioner::blocks);
  const auto fixed = fluid.velocity_condition_vertices();
  ASSERT_EQ(fixed.size(), static_cast<std::size_t>(fluid.mesh().n_owned_vertices));
  ImmersedConstraint all(fluid.mesh(), solid, {});
  ImmersedConstraint free_only(fluid.mesh(), solid, {}, fixed);
  // Wholly covered supports: x ∈ [0.65, 0.95] (7 columns), y ∈ [0, 0.25] (6 rows), of which
  // the row y = 0 lies on the wall.
  EXPECT_EQ(all.n_constrained(), 42);
  EXPECT_EQ(free_only.n_constrained(), 35);
  int on_wall = 0;
  for (const int v : free_only.constrained_vertices())
    on_wall += fixed[static_cast<std::size_t>(v)] != 0 || fluid.mesh().point(v)[1] < 1e-12;
  EXPECT_EQ(sum_all(on_wall), 0.0);
}

Mesh distributed_rectangle(double x0, double y0, double x1, double y1) {
  Mesh whole;
  if (coapt::rank_of(kWorld) == 0)
    whole = coapt::mesh::unstructured_rectangle(x0, y0, x1, y1, 0.045);
  return coapt::mesh::distribute(whole, kWorld, coapt::mesh::Partitioner::blocks);
}

TEST(CouplingConstraint, TwoSolidsCoveringOneBodyAreConstrainedAsTheBody) {
  // The square cut into two solids at x = 0.8 (a line of fluid vertices): alone, each covers
  // the whole support of 3 × 7 fluid vertices, and the column x = 0.8 half; together
  // (ConstraintGroup: B and D summed) they constrain the square's 7 × 7 vertices, transfer a
  // linear velocity given on both exactly, and take the same total force as the square.
  FluidModel fluid(read_case(), kWorld);
  fluid.start(0.0);
  const Mesh square = solid_square();
  const Mesh left = distributed_rectangle(0.6, 0.3, 0.8, 0.7);
  const Mesh right = distributed_rectangle(0.8, 0.3, 1.0, 0.7);
  ImmersedConstraint body(fluid.mesh(), square, {});
  ImmersedConstraint a(fluid.mesh(), left, {}), b(fluid.mesh(), right, {});
  EXPECT_EQ(a.n_constrained(), 21);
  EXPECT_EQ(b.n_constrained(), 21);
  ConstraintGroup group(fluid.mesh(), {&a, &b},
                        coapt::transfer::TransferOptions{}.coverage_threshold);
  group.combine();
  EXPECT_EQ(a.n_constrained(), 28) << "the shared column joins both";
  EXPECT_EQ(b.n_constrained(), 28);
  group.combine();  // idempotent
  EXPECT_EQ(a.n_constrained(), 28);
  const auto merged = group.merge({a.transfer_velocity(linear_velocity(a, left)),
                                   b.transfer_velocity(linear_velocity(b, right))});
  EXPECT_EQ(merged.vertices, body.constrained_vertices()) << "the square's vertices, each once";
  double error = 0;
  for (std::size_t q = 0; q < merged.vertices.size(); ++q) {
    const double x = fluid.mesh().point(merged.vertices[q])[0];
    const double y = fluid.mesh().point(merged.vertices[q])[1];
    error = std::max({error, std::abs(merged.velocities[2 * q] - (0.3 + 1.5 * x - 0.7 * y)),
                      std::abs(merged.velocities[2 * q + 1] - (-0.2 + 0.7 * x))});
  }
  MPI_Allreduce(MPI_IN_PLACE, &error, 1, MPI_DOUBLE, MPI_MAX, kWorld);
  EXPECT_LT(error, 1e-12);

  // At rest: the same fluid problem as the square's, so the same total force.
  const std::vector<double> zero_a(a.constrained_vertices().size() * 2, 0.0);
  const std::vector<double> zero_b(b.constrained_vertices().size() * 2, 0.0);
  const auto at_rest = group.merge({zero_a, zero_b});
  fluid.set_velocity_constraint(at_rest.vertices, at_rest.velocities);
  fluid.solve_steady("two solids");
  const auto reactions = fluid.constraint_reactions();
  std::vector<double> total(2, 0.0);
  for (std::size_t k = 0; k < 2; ++k) {
    auto& constraint = k == 0 ? a : b;
    const auto own = group.reactions_of(k, reactions);
    auto force = constraint.create_solid_vector();
    constraint.solid_force(constraint.multiplier(own), force);
    const auto sum = constraint.sum_components(force);
    const auto balance = constraint.sum_constrained(own);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(sum[i], balance[i], 1e-12 * std::abs(balance[0])) << "solid " << k;
      total[i] += sum[i];
    }
  }
  fluid.set_velocity_constraint(body.constrained_vertices(),
                                body.transfer_uniform_velocity({0.0, 0.0}));
  fluid.solve_steady("the square");
  const auto square_reaction = body.sum_constrained(fluid.constraint_reactions());
  for (int i = 0; i < 2; ++i)
    EXPECT_NEAR(total[i], square_reaction[i], 1e-9 * std::abs(square_reaction[0]))
        << "component " << i;
}

/// PETSc options for the lifetime of a test (cleared afterwards: every MPI test shares one
/// process and one options database).
class ScopedOptions {
 public:
  explicit ScopedOptions(std::vector<std::pair<std::string, std::string>> options)
      : options_(std::move(options)) {
    for (const auto& [name, value] : options_)
      PetscOptionsSetValue(nullptr, name.c_str(), value.c_str());
  }
  ~ScopedOptions() {
    for (const auto& option : options_) PetscOptionsClearValue(nullptr, option.first.c_str());
  }
  ScopedOptions(const ScopedOptions&) = delete;
  ScopedOptions& operator=(const ScopedOptions&) = delete;

 private:
  std::vector<std::pair<std::string, std::string>> options_;
};

TEST(CouplingConstraint, RestoredStepRepeatsBitForBit) {
  // A Krylov solver with a block-Jacobi preconditioner: its reductions run in a fixed order,
  // so a repeated solve is bitwise the same. The default parallel direct solver (MUMPS) is not
  // bitwise reproducible on more than one rank: its factorisation sums contributions in the
  // order the messages arrive.
  const ScopedOptions options({{"-fluid_ksp_type", "gmres"},
                               {"-fluid_pc_type", "bjacobi"},
                               {"-fluid_sub_pc_type", "lu"},
                               {"-fluid_ksp_rtol", "1e-12"},
                               {"-fluid_ksp_gmres_restart", "200"},
                               {"-fluid_ksp_max_it", "2000"}});
  FluidModel fluid(read_case(), kWorld);
  const Mesh solid = solid_square();
  ImmersedConstraint constraint(fluid.mesh(), solid, {});
  fluid.start(0.0);
  const auto at_rest = constraint.transfer_uniform_velocity({0.0, 0.0});
  fluid.set_velocity_constraint(constraint.constrained_vertices(), at_rest);
  for (int step = 0; step < 2; ++step) {
    fluid.begin_step(0.05);
    fluid.solve("step");
    fluid.commit_step();
  }
  // Third step: solve, keep the state, restore, solve again from the same history.
  fluid.begin_step(0.05);
  fluid.solve("step 3");
  coapt::OwnedVec first;
  VecDuplicate(fluid.state(), first.out());
  VecCopy(fluid.state(), first);
  const auto reactions = fluid.constraint_reactions();
  fluid.restore_step();
  EXPECT_DOUBLE_EQ(fluid.time(), 0.1);
  fluid.begin_step(0.05);
  fluid.solve("step 3 again");
  double difference = 0;
  VecAXPY(first, -1.0, fluid.state());
  VecNorm(first, NORM_INFINITY, &difference);
  EXPECT_EQ(difference, 0.0);
  const auto again = fluid.constraint_reactions();
  ASSERT_EQ(again.size(), reactions.size());
  double reaction_difference = 0;
  for (std::size_t k = 0; k < again.size(); ++k)
    reaction_difference = std::max(reaction_difference, std::abs(again[k] - reactions[k]));
  EXPECT_EQ(sum_all(reaction_difference), 0.0);
  fluid.commit_step();
  EXPECT_EQ(fluid.steps(), 3);
  EXPECT_NEAR(fluid.time(), 0.15, 1e-15);
  EXPECT_GT(fluid.kinetic_energy(), 0.0);
}

TEST(CouplingConstraint, BoundaryForceAfterCommitIsTheCommittedSteps) {
  // The flow starts from rest (the inflow switched on at t = 0), so the time derivative is a
  // large part of the wall force in the first steps. The force read after commit_step must be
  // the one of the step just solved: the residual with that step's history (uⁿ⁻¹, uⁿ⁻²),
  // not with a history that already holds the committed state.
  FluidModel fluid(read_case(), kWorld);
  fluid.start(0.0);
  const auto* bottom = fluid.mesh().find_group("bottom");
  ASSERT_NE(bottom, nullptr);
  std::vector<double> committed;
  for (int step = 1; step <= 3; ++step) {       // BDF1, then BDF2
    fluid.begin_step(step == 3 ? 0.03 : 0.05);  // and a changed step size
    fluid.solve("step");
    const auto during = fluid.boundary_force(bottom->tag);
    fluid.commit_step();
    committed = fluid.boundary_force(bottom->tag);
    for (int i = 0; i < 2; ++i)
      EXPECT_NEAR(committed[i], during[i], 1e-12 * std::abs(during[0]))
          << "step " << step << ", component " << i;
  }
  EXPECT_GT(committed[0], 0.0);  // the flow drags the bottom wall downstream
  // A trial step that is dropped leaves the committed step's force.
  fluid.begin_step(0.05);
  fluid.solve("step 4");
  const auto trial = fluid.boundary_force(bottom->tag);
  fluid.restore_step();
  const auto restored = fluid.boundary_force(bottom->tag);
  for (int i = 0; i < 2; ++i) EXPECT_EQ(restored[i], committed[i]) << "component " << i;
  EXPECT_NE(trial[0], committed[0]);
}

/// The effective weight s/(1 + s) of each owned fluid vertex: 1 constrained, 0 untouched.
std::vector<double> effective_weights(const ImmersedConstraint& constraint, int n_owned) {
  std::vector<double> weight(static_cast<std::size_t>(n_owned), 0.0);
  for (const int v : constraint.constrained_vertices()) weight[static_cast<std::size_t>(v)] = 1.0;
  const auto& partial = constraint.partial_vertices();
  for (std::size_t q = 0; q < partial.size(); ++q) {
    const double s = constraint.partial_weights()[q];
    weight[static_cast<std::size_t>(partial[q])] = s / (1.0 + s);
  }
  return weight;
}

/// Drag on the square held at rest, with the covered-node rule `threshold` and partial
/// coverage from `partial_from` (≥ threshold: none); the force balance is checked on the way.
double square_drag(double threshold, double partial_from) {
  FluidModel fluid(read_case(), kWorld);
  const Mesh solid = solid_square();
  coapt::transfer::TransferOptions options;
  options.coverage_threshold = threshold;
  ImmersedConstraint constraint(fluid.mesh(), solid, options, {}, partial_from);
  fluid.start(0.0);
  fluid.set_velocity_constraint(constraint.constrained_vertices(),
                                constraint.transfer_uniform_velocity({0.0, 0.0}));
  fluid.set_velocity_penalty(constraint.partial_vertices(), constraint.partial_weights(),
                             constraint.partial_uniform_velocity({0.0, 0.0}));
  fluid.solve_steady("immersed square");
  const auto reactions = fluid.constraint_reactions();
  const auto penalty = fluid.penalty_reactions();
  auto force = constraint.create_solid_vector();
  constraint.solid_force(constraint.multiplier(reactions), force);
  constraint.add_partial_force(penalty, force);
  const auto total = constraint.sum_components(force);
  auto expected = constraint.sum_constrained(reactions);
  const auto partial = constraint.sum_partial(penalty);
  for (int i = 0; i < 2; ++i) {
    expected[i] += partial[i];
    EXPECT_NEAR(total[i], expected[i], 1e-12 * std::abs(expected[0])) << "component " << i;
  }
  if (partial_from < threshold) {
    EXPECT_GT(constraint.n_partial(), 0);
    EXPECT_GT(std::abs(partial[0]), 0.0) << "the partly covered nodes carry load";
  }
  return total[0];
}

TEST(CouplingConstraint, PartlyCoveredNodesFollowTheirCoverage) {
  FluidModel fluid(read_case(), kWorld);
  const Mesh solid = solid_square();
  coapt::transfer::TransferOptions options;
  options.coverage_threshold = 0.9;
  const double from = 0.1;
  ImmersedConstraint constraint(fluid.mesh(), solid, options, {}, from);
  ASSERT_GT(constraint.n_partial(), 0);
  // s/(1 + s) = (c − from)/(t − from): linear in the coverage between the two fractions
  const PetscScalar* coverage = nullptr;
  VecGetArrayRead(constraint.transfer().coverage(), &coverage);
  double weight_error = 0;
  const auto& partial = constraint.partial_vertices();
  for (std::size_t q = 0; q < partial.size(); ++q) {
    const double c = coverage[partial[q]], s = constraint.partial_weights()[q];
    EXPECT_GT(c, from);
    EXPECT_LT(c, 0.9);
    EXPECT_GT(s, 0.0);
    weight_error = std::max(weight_error, std::abs(s / (1 + s) - (c - from) / (0.9 - from)));
  }
  VecRestoreArrayRead(constraint.transfer().coverage(), &coverage);
  MPI_Allreduce(MPI_IN_PLACE, &weight_error, 1, MPI_DOUBLE, MPI_MAX, kWorld);
  EXPECT_LT(weight_error, 1e-9);
  for (const int v : constraint.constrained_vertices())
    EXPECT_FALSE(std::binary_search(partial.begin(), partial.end(), v));
  // The targets are weighted averages of the solid's velocity: within the range of the linear
  // field over the square, 0.3 + 1.5 x − 0.7 y ∈ [0.71, 1.59], −0.2 + 0.7 x ∈ [0.22, 0.5].
  const auto velocity = linear_velocity(constraint, solid);
  const auto targets = constraint.partial_velocity(velocity);
  for (std::size_t q = 0; q < partial.size(); ++q) {
    EXPECT_GE(targets[2 * q], 0.71 - 1e-12);
    EXPECT_LE(targets[2 * q], 1.59 + 1e-12);
    EXPECT_GE(targets[2 * q + 1], 0.22 - 1e-12);
    EXPECT_LE(targets[2 * q + 1], 0.5 + 1e-12);
  }
  // Moving the square by h/50 changes every node's effective weight by little: no node
  // enters or leaves the coupling with a jump (the plain covered-node rule jumps by 1).
  const auto before = effective_weights(constraint, fluid.mesh().n_owned_vertices);
  Mesh moved = solid;
  for (std::size_t k = 0; k < moved.coordinates.size(); k += 2) moved.coordinates[k] += 1e-3;
  constraint.update_solid(moved);
  const auto after = effective_weights(constraint, fluid.mesh().n_owned_vertices);
  double change = 0;
  for (std::size_t v = 0; v < before.size(); ++v)
    change = std::max(change, std::abs(after[v] - before[v]));
  MPI_Allreduce(MPI_IN_PLACE, &change, 1, MPI_DOUBLE, MPI_MAX, kWorld);
  EXPECT_GT(change, 0.0);
  EXPECT_LT(change, 0.1);
}

TEST(CouplingConstraint, PartialCoverageLiesBetweenTheRulesItBlends) {
  // The penalty's nodes are those the rule with threshold 0.1 adds to the rule with 0.9, held
  // less firmly: the drag lies between the two rules' drags.
  const double inner = square_drag(0.9, 1.0);
  const double outer = square_drag(0.1, 1.0);
  const double blended = square_drag(0.9, 0.1);
  if (coapt::rank_of(kWorld) == 0)
    std::printf("square drag: threshold 0.9 %.8e, 0.1 %.8e, partial 0.1-0.9 %.8e\n", inner, outer,
                blended);
  EXPECT_LT(inner, outer);
  EXPECT_GT(blended, inner);
  EXPECT_LT(blended, outer);
}

TEST(CouplingConstraint, StiffPenaltyIsTheConstraint) {
  // The wholly covered nodes held by a penalty of weight 1e8 instead of the constraint: the
  // same velocities (zero) and reactions up to the penalty's compliance.
  double constrained_force = 0, penalty_force = 0, held = 0;
  for (const bool penalty : {false, true}) {
    FluidModel fluid(read_case(), kWorld);
    const Mesh solid = solid_square();
    ImmersedConstraint constraint(fluid.mesh(), solid, {});
    fluid.start(0.0);
    const auto& vertices = constraint.constrained_vertices();
    const auto zero = constraint.transfer_uniform_velocity({0.0, 0.0});
    if (penalty)
      fluid.set_velocity_penalty(vertices, std::vector<double>(vertices.size(), 1e8), zero);
    else
      fluid.set_velocity_constraint(vertices, zero);
    fluid.solve_steady("immersed square");
    const auto reactions = penalty ? fluid.penalty_reactions() : fluid.constraint_reactions();
    double sum = 0;
    for (std::size_t q = 0; q < vertices.size(); ++q) sum += reactions[2 * q];
    (penalty ? penalty_force : constrained_force) = sum_all(sum);
    if (penalty) {
      coapt::fem::LocalValues state(fluid.state());
      for (const int v : vertices)
        held = std::max({held, std::abs(state[3 * static_cast<std::size_t>(v)]),
                         std::abs(state[3 * static_cast<std::size_t>(v) + 1])});
      MPI_Allreduce(MPI_IN_PLACE, &held, 1, MPI_DOUBLE, MPI_MAX, kWorld);
    }
  }
  EXPECT_GT(constrained_force, 0.0);
  EXPECT_NEAR(penalty_force, constrained_force, 1e-6 * constrained_force);
  EXPECT_LT(held, 1e-7);
}

/// The penalty's stiffness κ_k = r_k / (u_k − w_k) at the partly covered nodes of the square
/// held at rest, after one transient step of size dt from rest with the penalty's time scale tau
/// (0: the step's own inertia); the nodes whose velocity is below 1e-6 are left out (nan).
std::vector<double> penalty_stiffness(double dt, double tau) {
  FluidModel fluid(read_case(), kWorld);
  const Mesh solid = solid_square();
  coapt::transfer::TransferOptions options;
  options.coverage_threshold = 0.9;
  ImmersedConstraint constraint(fluid.mesh(), solid, options, {}, 0.1);
  fluid.start(0.0);
  fluid.set_velocity_constraint(constraint.constrained_vertices(),
                                constraint.transfer_uniform_velocity({0.0, 0.0}));
  fluid.set_velocity_penalty(constraint.partial_vertices(), constraint.partial_weights(),
                             constraint.partial_uniform_velocity({0.0, 0.0}), tau);
  fluid.begin_step(dt);
  fluid.solve("step");
  const auto reactions = fluid.penalty_reactions();
  coapt::fem::LocalValues state(fluid.state());
  const auto& partial = constraint.partial_vertices();
  std::vector<double> stiffness(partial.size(), std::nan(""));
  for (std::size_t q = 0; q < partial.size(); ++q) {
    const double u = state[3 * static_cast<std::size_t>(partial[q])];
    if (std::abs(u) > 1e-6) stiffness[q] = reactions[2 * q] / u;
  }
  return stiffness;
}

TEST(CouplingConstraint, PenaltyTimeScaleFixesItsStiffness) {
  // Without a time scale the inertial part ρ α₀ m / Δt doubles when Δt halves; with one it is
  // ρ m / τ for every Δt. The viscous part (μ = 0.01 against ρ m / Δt ≈ 0.05–0.1 here) is the
  // same in both.
  const auto own_long = penalty_stiffness(0.05, 0.0), own_short = penalty_stiffness(0.025, 0.0);
  const auto fixed_long = penalty_stiffness(0.05, 0.04),
             fixed_short = penalty_stiffness(0.025, 0.04);
  ASSERT_EQ(own_long.size(), own_short.size());
  double fixed_change = 0, own_ratio_low = 1e300, own_ratio_high = 0;
  long long compared = 0;
  for (std::size_t q = 0; q < own_long.size(); ++q) {
    if (std::isnan(own_long[q]) || std::isnan(own_short[q]) || std::isnan(fixed_long[q]) ||
        std::isnan(fixed_short[q]))
      continue;
    ++compared;
    EXPECT_GT(fixed_long[q], 0.0);
    fixed_change = std::max(fixed_change, std::abs(fixed_short[q] / fixed_long[q] - 1.0));
    own_ratio_low = std::min(own_ratio_low, own_short[q] / own_long[q]);
    own_ratio_high = std::max(own_ratio_high, own_short[q] / own_long[q]);
  }
  MPI_Allreduce(MPI_IN_PLACE, &compared, 1, MPI_LONG_LONG, MPI_SUM, kWorld);
  MPI_Allreduce(MPI_IN_PLACE, &fixed_change, 1, MPI_DOUBLE, MPI_MAX, kWorld);
  MPI_Allreduce(MPI_IN_PLACE, &own_ratio_low, 1, MPI_DOUBLE, MPI_MIN, kWorld);
  MPI_Allreduce(MPI_IN_PLACE, &own_ratio_high, 1, MPI_DOUBLE, MPI_MAX, kWorld);
  if (coapt::rank_of(kWorld) == 0)
    std::printf(
        "penalty stiffness over %lld nodes: dt/2 changes it by x%.6f..x%.6f without a "
        "time scale, by at most %.3e with tau = 0.04\n",
        compared, own_ratio_low, own_ratio_high, fixed_change);
  EXPECT_GT(compared, 0);
  EXPECT_LT(fixed_change, 1e-9);
  EXPECT_GT(own_ratio_low, 1.5);  // nearly 2: the viscous part does not change
  EXPECT_LT(own_ratio_high, 2.0 + 1e-9);
}

/// The channel [0, 2] × [0, 1] (h = 0.05) driven by a pressure of 1 at its left end and closed
/// by a band 0.95 ≤ x ≤ 1.05 of vertices held at rest (as a closed valve's leaflets are, the
/// wall vertices left to their no-slip condition), steady, with the continuity equation of the
/// band's cells scaled by `factor` (fluid.covered_continuity_factor). `covered` ≥ 0: the
/// fraction of the cells between x = 0.94 and 1.06 the solids cover, given to the fluid
/// (`elsewhere` for the others); < 0: not given (the vertex rule alone). Returns the flow out at
/// the right end and the band's pressure range (min, max).
struct ClosedBand {
  double leak = 0, band_min = 0, band_max = 0;
};
ClosedBand closed_band(double factor, double covered = -1, double elsewhere = 0) {
  const std::string text = R"(
mesh: {type: rectangle, lower: [0, 0], upper: [2, 1], cells: [40, 20]}
fluid: {density: 1.0, viscosity: 0.01, covered_continuity_factor: )" +
                           std::to_string(factor) + R"(}
boundary:
  - {group: bottom, type: no_slip}
  - {group: top, type: no_slip}
outlets:
  - {group: left, type: traction, pressure: 1.0, backflow: 0}
  - {group: right, type: do_nothing, backflow: 0}
)";
  auto document = coapt::config::Document::from_string(text, "closed_band.yaml");
  const auto root = document.root();
  FluidModel fluid(FluidCase::read(root, root.section("fluid")), kWorld);
  const Mesh& mesh = fluid.mesh();
  std::vector<int> band;
  for (int v = 0; v < mesh.n_owned_vertices; ++v) {
    const auto x = mesh.point(v);
    if (x[0] > 0.94 && x[0] < 1.06 && x[1] > 1e-9 && x[1] < 1 - 1e-9) band.push_back(v);
  }
  std::vector<double> coverage;
  if (covered >= 0)
    for (int c = 0; c < mesh.n_owned_cells; ++c) {
      bool inside = true;
      for (const int v : mesh.cell(c)) inside = inside && std::fabs(mesh.point(v)[0] - 1) < 0.06;
      coverage.push_back(inside ? covered : elsewhere);
    }
  fluid.start(0.0);
  fluid.set_velocity_constraint(band, std::vector<double>(2 * band.size(), 0.0), coverage);
  fluid.solve_steady("closed band");
  ClosedBand result;
  result.leak = fluid.outlet_flow(1);
  coapt::fem::LocalValues state(fluid.state());
  double low = 1e300, high = -1e300;
  for (const int v : band) {
    low = std::min(low, state[3 * static_cast<std::size_t>(v) + 2]);
    high = std::max(high, state[3 * static_cast<std::size_t>(v) + 2]);
  }
  MPI_Allreduce(&low, &result.band_min, 1, MPI_DOUBLE, MPI_MIN, kWorld);
  MPI_Allreduce(&high, &result.band_max, 1, MPI_DOUBLE, MPI_MAX, kWorld);
  return result;
}

TEST(CouplingConstraint, CoveredContinuityFactorScalesTheLeakThroughAClosedBand) {
  // Through a band held at rest the flow passes only as the PSPG flux τ_M ∇p of the band's
  // cells: scaling their continuity equation by κ scales that flux by κ, so the resistance to
  // the leak, Δp/Q, is R_outside + R_band/κ (affine in 1/κ): its steps from κ = 1 to 0.1 and
  // from 0.1 to 0.01 are in the ratio (100 − 10)/(10 − 1) = 10. The band's pressure stays
  // between the ends' (0 and 1).
  const ClosedBand full = closed_band(1.0), tenth = closed_band(0.1), hundredth = closed_band(0.01);
  const double first_step = 1 / tenth.leak - 1 / full.leak,
               second_step = 1 / hundredth.leak - 1 / tenth.leak;
  if (coapt::rank_of(kWorld) == 0)
    std::printf(
        "closed band: leak %.6e (1), %.6e (0.1), %.6e (0.01); resistance steps %.4f, %.4f "
        "(ratio %.4f); pressure in the band [%.4f, %.4f] (0.01)\n",
        full.leak, tenth.leak, hundredth.leak, first_step, second_step, second_step / first_step,
        hundredth.band_min, hundredth.band_max);
  EXPECT_GT(full.leak, 0.0);
  EXPECT_LT(tenth.leak, 0.2 * full.leak);
  EXPECT_NEAR(second_step / first_step, 10.0, 0.2);
  for (const auto& band : {full, tenth, hundredth}) {
    EXPECT_GT(band.band_min, 0.0);
    EXPECT_LT(band.band_max, 1.0);
  }
  // fluid.covered_continuity_coverage (default 1 − 1e-6): κ applies to the cells the solids
  // cover wholly (so with every cell covered, to the vertex rule's cells), and a cell they
  // cover only in part (a gap between two leaflets) keeps its whole continuity equation: with
  // the band's cells 0.9 covered (and no other), the leak of κ = 1. The ghost cells' fractions come
  // from their owners (the matrix is assembled over them too): the same leak on any rank count.
  const ClosedBand covered = closed_band(0.01, 1.0, 1.0), partly = closed_band(0.01, 0.9, 0.0);
  if (coapt::rank_of(kWorld) == 0)
    std::printf(
        "closed band, kappa 0.01: leak %.6e with every cell covered, %.6e with the "
        "band's cells 0.9 covered\n",
        covered.leak, partly.leak);
  EXPECT_NEAR(covered.leak, hundredth.leak, 1e-9 * hundredth.leak);
  EXPECT_NEAR(partly.leak, full.leak, 1e-9 * full.leak);
}

}  // namespace
