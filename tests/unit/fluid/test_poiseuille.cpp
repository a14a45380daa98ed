// The fluid operator on a channel [0, 4] × [0, 1]: Poiseuille flow u = 4U y(1 − y), p = 8μU(4 − x)
// (do-nothing outlet at x = 4 makes p = 0 there) with a parabolic inflow and no-slip walls.
// P1-P1 does not hold the parabola, so the nodal error must fall at second order; the wall
// forces and the reaction forces of a velocity constraint must match the exact tractions.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <numeric>

#include "coapt/core/context.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fluid/navier_stokes.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"

namespace {

using coapt::fluid::FluidParameters;
using coapt::fluid::NavierStokes;
using coapt::fluid::TimeLevel;
using coapt::mesh::Mesh;

constexpr double kLength = 4.0, kPeak = 1.0, kViscosity = 0.5;

Mesh channel(int n_across) {
  Mesh whole;
  if (coapt::rank_of(MPI_COMM_WORLD) == 0)
    whole = coapt::mesh::structured_rectangle(0, 0, kLength, 1, 4 * n_across, n_across);
  return coapt::mesh::distribute(whole, MPI_COMM_WORLD);
}

double exact_u(double y) {
  return 4 * kPeak * y * (1 - y);
}
double exact_p(double x) {
  return 8 * kViscosity * kPeak * (kLength - x);
}

struct Solved {
  double velocity_error = 0;  ///< max over vertices |u_h − u| / U
  double pressure_error = 0;  ///< max over vertices |p_h − p| / p(0)
};

/// Solves on a channel; the bottom wall is a Dirichlet group or, with `constrain_bottom`, a
/// velocity constraint whose reactions are returned in `reactions` (summed).
Solved solve(const Mesh& mesh, bool convection, bool constrain_bottom,
             std::vector<double>* bottom_force = nullptr,
             std::vector<double>* reactions = nullptr) {
  FluidParameters parameters;
  parameters.viscosity = kViscosity;
  parameters.convection = convection;
  NavierStokes fluid(mesh, parameters);
  const int n = 3;
  // Tags of structured_rectangle: left 1, right 2, bottom 3, top 4.
  std::vector<char> fixed(static_cast<std::size_t>(mesh.n_owned_vertices), 0);
  std::vector<int> bottom;
  for (int f = 0; f < mesh.n_facets(); ++f)
    for (int a = 0; a < 2; ++a) {
      const int v = mesh.facets[static_cast<std::size_t>(f) * 2 + a];
      if (v >= mesh.n_owned_vertices) continue;
      const int tag = mesh.facet_tags[f];
      if (tag == 1 || tag == 4 || (tag == 3 && !constrain_bottom)) fixed[v] = 1;
      if (tag == 3 && constrain_bottom) bottom.push_back(v);
    }
  std::sort(bottom.begin(), bottom.end());
  bottom.erase(std::unique(bottom.begin(), bottom.end()), bottom.end());
  std::vector<PetscInt> dofs;
  for (int v = 0; v < mesh.n_owned_vertices; ++v) {
    if (!fixed[v]) continue;
    const double x = mesh.point(v)[0], y = mesh.point(v)[1];
    const double u = x < 1e-12 ? exact_u(y) : 0.0;  // inflow profile, walls at rest
    VecSetValue(fluid.state(), mesh.global_vertex[v] * n, u, INSERT_VALUES);
    dofs.push_back(mesh.global_vertex[v] * n);
    dofs.push_back(mesh.global_vertex[v] * n + 1);
  }
  VecAssemblyBegin(fluid.state());
  VecAssemblyEnd(fluid.state());
  coapt::fem::update_ghosts(fluid.state());
  fluid.set_dirichlet_dofs(dofs);
  // Constrained bottom vertices keep u = 0 except those the inflow fixes (x = 0).
  std::vector<int> constrained;
  for (int v : bottom)
    if (!fixed[v]) constrained.push_back(v);
  fluid.set_velocity_constraint(constrained, std::vector<double>(constrained.size() * 2, 0.0));

  const TimeLevel steady;
  const auto report = fluid.solve(steady, "poiseuille");
  EXPECT_LE(report.iterations, convection ? 8 : 2);
  Solved result;
  {
    coapt::fem::LocalValues state(fluid.state());
    for (int v = 0; v < mesh.n_owned_vertices; ++v) {
      const double x = mesh.point(v)[0], y = mesh.point(v)[1];
      const std::size_t base = static_cast<std::size_t>(v) * n;
      result.velocity_error =
          std::max({result.velocity_error, std::abs(state[base] - exact_u(y)) / kPeak,
                    std::abs(state[base + 1]) / kPeak});
      result.pressure_error =
          std::max(result.pressure_error, std::abs(state[base + 2] - exact_p(x)) / exact_p(0));
    }
  }
  double errors[2] = {result.velocity_error, result.pressure_error};
  MPI_Allreduce(MPI_IN_PLACE, errors, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  result = {errors[0], errors[1]};
  if (bottom_force) *bottom_force = fluid.boundary_force(3, steady);
  if (reactions) {
    const auto local = fluid.constraint_reactions(steady);
    std::vector<double> sum(2, 0.0);
    for (std::size_t k = 0; k < local.size(); ++k) sum[k % 2] += local[k];
    MPI_Allreduce(MPI_IN_PLACE, sum.data(), 2, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    *reactions = sum;
  }
  return result;
}

TEST(FluidPoiseuille, StokesConvergesAtSecondOrderAtTheVertices) {
  const auto coarse = solve(channel(4), false, false);
  const auto fine = solve(channel(8), false, false);
  std::printf("Stokes Poiseuille: velocity error %.3e -> %.3e, pressure error %.3e -> %.3e\n",
              coarse.velocity_error, fine.velocity_error, coarse.pressure_error,
              fine.pressure_error);
  EXPECT_LT(coarse.velocity_error, 0.05);  // 4 cells across: within 5 % of the peak
  EXPECT_LT(fine.velocity_error, coarse.velocity_error / 3.0);
  EXPECT_LT(fine.pressure_error, coarse.pressure_error / 2.0);
}

TEST(FluidPoiseuille, NavierStokesKeepsThePoiseuilleSolution) {
  // u·∇u = 0 for Poiseuille flow: Newton with convection reaches the same accuracy.
  const auto stokes = solve(channel(4), false, false);
  const auto navier = solve(channel(4), true, false);
  EXPECT_LT(navier.velocity_error, 0.05);
  EXPECT_NEAR(navier.velocity_error, stokes.velocity_error, 0.02);
}

TEST(FluidPoiseuille, WallForceAndConstraintReactionsMatchTheExactTraction) {
  // Force of the fluid on the bottom wall, F = ∫ χ t ds with t the traction on the wall and χ
  // the P1 indicator of the wall's vertices: shear μ ∂_y u = 4μU along x, pressure −p along y.
  // χ also reaches into the inlet at the corner (0, 0) (a hat of height h_y = 1/8), where the
  // traction on the body side is +p(0) e_x... with the outward normal −e_x of the fluid the
  // body force gains −p(0) h_y/2 in x. The constraint excludes that corner vertex, so its χ
  // drops the first wall segment's hat: ∫_0^h_x (1 − x/h_x)(shear, −p) dx.
  const int n_across = 8;
  const double h_x = kLength / (4 * n_across), h_y = 1.0 / n_across;
  const double pressure_slope = 8 * kViscosity * kPeak;  // p = P (L − x)
  const double shear = 4 * kViscosity * kPeak;           // per unit length
  const double wall_x = shear * kLength - exact_p(0) * h_y / 2;
  const double wall_y = -pressure_slope * kLength * kLength / 2;
  const double corner_hat_y = pressure_slope * (kLength * h_x / 2 - h_x * h_x / 6);
  const double constrained_x = shear * (kLength - h_x / 2);
  const double constrained_y = wall_y + corner_hat_y;
  std::vector<double> force, reactions;
  solve(channel(n_across), false, false, &force, nullptr);
  std::printf("bottom wall force (%.5f, %.5f), exact (%.5f, %.5f)\n", force[0], force[1], wall_x,
              wall_y);
  EXPECT_NEAR(force[0], wall_x, 0.02 * std::abs(wall_x));
  EXPECT_NEAR(force[1], wall_y, 0.02 * std::abs(wall_y));
  std::vector<double> constrained_force;
  solve(channel(n_across), false, true, &constrained_force, &reactions);
  std::printf("constraint reactions (%.5f, %.5f), exact (%.5f, %.5f)\n", reactions[0], reactions[1],
              constrained_x, constrained_y);
  // The constrained solve is the Dirichlet solve: same wall force.
  EXPECT_NEAR(constrained_force[0], force[0], 1e-8 * std::abs(force[0]));
  EXPECT_NEAR(constrained_force[1], force[1], 1e-8 * std::abs(force[1]));
  EXPECT_NEAR(reactions[0], constrained_x, 0.02 * std::abs(constrained_x));
  EXPECT_NEAR(reactions[1], constrained_y, 0.02 * std::abs(constrained_y));
}

}  // namespace
