// The fluid's reuse of a time step's preconditioner (FluidParameters::reuse_preconditioner):
// a transient channel flow past an immersed obstacle whose velocity changes between the two
// solves of each step (as in coupling iterations) gives the same states with the reused
// factorisation (2D, LU) or fieldsplit (3D, the default's AMG and S_p) as when every Newton
// iteration builds a new one, with fewer builds; a factorisation too stale for GMRES within
// its cap is replaced within the same solve.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>

#include "coapt/core/context.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fluid/navier_stokes.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"

namespace {

using coapt::OwnedVec;
using coapt::fluid::FluidParameters;
using coapt::fluid::NavierStokes;
using coapt::fluid::TimeLevel;
using coapt::mesh::Mesh;

/// [0, 4] × [0, 1] (× [0, 1] in 3D).
Mesh channel(int dim = 2) {
  Mesh whole;
  if (coapt::rank_of(MPI_COMM_WORLD) == 0)
    whole = dim == 2 ? coapt::mesh::structured_rectangle(0, 0, 4, 1, 48, 12)
                     : coapt::mesh::structured_box(0, 0, 0, 4, 1, 1, 16, 4, 4);
  return coapt::mesh::distribute(whole, MPI_COMM_WORLD);
}

/// Inflow 4y(1 − y) (times 4z(1 − z) in 3D) on the left (tag 1), no slip on the other walls,
/// the right side (2) natural.
void set_boundary(const Mesh& mesh, NavierStokes& fluid) {
  const int dim = mesh.dim, n = dim + 1;
  std::vector<PetscInt> dofs;
  for (int f = 0; f < mesh.n_facets(); ++f) {
    const int tag = mesh.facet_tags[f];
    if (tag == 2) continue;
    for (int a = 0; a < dim; ++a) {
      const int v = mesh.facets[static_cast<std::size_t>(f) * dim + a];
      if (v >= mesh.n_owned_vertices) continue;
      const auto point = mesh.point(v);
      double u = point[0] < 1e-12 ? 4 * point[1] * (1 - point[1]) : 0.0;
      if (dim == 3) u *= 4 * point[2] * (1 - point[2]);
      for (int i = 0; i < dim; ++i) {
        const PetscInt dof = mesh.global_vertex[v] * n + i;
        VecSetValue(fluid.state(), dof, i == 0 ? u : 0.0, INSERT_VALUES);
        dofs.push_back(dof);
      }
    }
  }
  VecAssemblyBegin(fluid.state());
  VecAssemblyEnd(fluid.state());
  coapt::fem::update_ghosts(fluid.state());
  fluid.set_dirichlet_dofs(dofs);
}

/// Owned vertices within `radius` of (cx, 0.5) (or (cx, 0.5, 0.5)), not on the boundary.
std::vector<int> obstacle(const Mesh& mesh, double cx, double radius) {
  std::vector<int> vertices;
  for (int v = 0; v < mesh.n_owned_vertices; ++v) {
    const auto point = mesh.point(v);
    double square = (point[0] - cx) * (point[0] - cx) + (point[1] - 0.5) * (point[1] - 0.5);
    if (mesh.dim == 3) square += (point[2] - 0.5) * (point[2] - 0.5);
    if (std::sqrt(square) < radius) vertices.push_back(v);
  }
  return vertices;
}

struct Steps {
  std::vector<double> state;  ///< the owned values after the last step
  int setups = 0, newton_iterations = 0;
};

/// `steps` BDF1 steps of Δt = 0.05, each solved twice, the obstacle moving at a velocity
/// that changes between the solves.
Steps run_steps(const Mesh& mesh, int reuse, int steps) {
  const int dim = mesh.dim;
  FluidParameters parameters;
  parameters.density = 1.0;
  parameters.viscosity = 0.01;
  parameters.reuse_preconditioner = reuse;
  NavierStokes fluid(mesh, parameters);
  set_boundary(mesh, fluid);
  const auto body = obstacle(mesh, 1.0, dim == 3 ? 0.3 : 0.2);  // 7 vertices in 3D
  OwnedVec previous;
  VecDuplicate(fluid.state(), previous.out());
  TimeLevel level;
  level.time_step = 0.05;
  level.alpha = {1.0, -1.0, 0.0};
  level.previous = previous;
  Steps result;
  for (int step = 0; step < steps; ++step) {
    VecCopy(fluid.state(), previous);
    coapt::fem::update_ghosts(previous);
    fluid.refresh_preconditioner();
    for (int solve = 0; solve < 2; ++solve) {
      const double vy = 0.1 * std::sin(step + 0.5 * solve);
      std::vector<double> velocities;
      for (std::size_t k = 0; k < body.size(); ++k) {
        velocities.insert(velocities.end(), {0.2, vy});
        if (dim == 3) velocities.push_back(0.0);
      }
      fluid.set_velocity_constraint(body, velocities);
      const auto report = fluid.solve(level, "reuse test");
      result.setups += report.preconditioner_setups;
      result.newton_iterations += report.iterations;
    }
  }
  coapt::fem::LocalValues state(fluid.state());
  const auto values = state.values();
  result.state.assign(values.begin(), values.begin() + mesh.n_owned_vertices * (dim + 1));
  return result;
}

double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double difference = 0, size = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    difference = std::max(difference, std::abs(a[k] - b[k]));
    size = std::max(size, std::abs(b[k]));
  }
  double values[2] = {difference, size};
  MPI_Allreduce(MPI_IN_PLACE, values, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return values[0] / values[1];
}

/// `steps` steps with the preconditioner built at every Newton iteration and reused
/// (reuse_preconditioner 10): the states agree to `tolerance`, the reuse builds fewer (and
/// at least one per step).
void expect_reuse_saves_builds(const Mesh& mesh, int steps, double tolerance, const char* what) {
  const Steps fresh = run_steps(mesh, 0, steps);
  const Steps reused = run_steps(mesh, 10, steps);
  const double difference = max_difference(reused.state, fresh.state);
  std::printf(
      "reuse (%s): %d builds for %d Newton iterations (fresh: %d for %d); states differ "
      "by %.3e\n",
      what, reused.setups, reused.newton_iterations, fresh.setups, fresh.newton_iterations,
      difference);
  EXPECT_LT(difference, tolerance);
  EXPECT_EQ(fresh.setups, fresh.newton_iterations);
  EXPECT_GE(reused.setups, steps);  // built afresh at every step
  EXPECT_LT(reused.setups, fresh.setups);
}

TEST(FluidReusePreconditioner, ReusedFactorisationGivesTheFreshStatesWithFewerFactorisations) {
  expect_reuse_saves_builds(channel(), 4, 1e-9, "2D, LU");
}

TEST(FluidReusePreconditioner, ReusedFieldsplitGivesTheFreshStatesWithFewerBuilds) {
  // 3D: GMRES (relative tolerance 1e-6) with the Schur fieldsplit; Newton stops at a relative
  // residual of 1e-8, so the states need only agree to about that, not to round-off.
  expect_reuse_saves_builds(channel(3), 3, 1e-6, "3D, fieldsplit");
}

TEST(FluidReusePreconditioner, StaleFactorisationIsReplacedWithinTheSolve) {
  // A cap of 4 GMRES iterations (4 × reuse_preconditioner) on a factorisation from before
  // the obstacle existed: the solve factors afresh and reaches the fresh solve's state.
  const Mesh mesh = channel();
  FluidParameters parameters;
  parameters.viscosity = 0.01;
  NavierStokes reference(mesh, parameters);
  parameters.reuse_preconditioner = 1;
  NavierStokes fluid(mesh, parameters);
  TimeLevel level;
  level.time_step = 0.05;
  level.alpha = {1.0, -1.0, 0.0};
  OwnedVec previous;
  VecDuplicate(fluid.state(), previous.out());
  level.previous = previous;
  const auto body = obstacle(mesh, 2.0, 0.3);
  const std::vector<double> velocities(body.size() * 2, 0.0);
  std::vector<std::vector<double>> states;
  int setups = 0;
  for (NavierStokes* model : {&reference, &fluid}) {
    set_boundary(mesh, *model);
    model->refresh_preconditioner();
    model->set_velocity_constraint({}, {});
    model->solve(level, "no obstacle");
    model->set_velocity_constraint(body, velocities);
    if (model == &reference) model->refresh_preconditioner();
    setups = model->solve(level, "obstacle").preconditioner_setups;
    coapt::fem::LocalValues state(model->state());
    const auto values = state.values();
    states.emplace_back(values.begin(), values.begin() + mesh.n_owned_vertices * 3);
  }
  int any_body = body.empty() ? 0 : 1;
  MPI_Allreduce(MPI_IN_PLACE, &any_body, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  ASSERT_EQ(any_body, 1);
  EXPECT_GE(setups, 1);
  EXPECT_LT(max_difference(states[1], states[0]), 1e-9);
}

}  // namespace
