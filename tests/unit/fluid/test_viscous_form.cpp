// The two forms of the viscous term (kernels.hpp): Laplace μ∇w:∇u and symmetric (stress)
// 2μ∇w:ε(u). Element level: the Galerkin viscous residual of a linear velocity against its
// closed form in both forms, zero for a rigid rotation in the stress form only, and the
// stress-form Jacobian against central finite differences. Operator level: Poiseuille flow
// with Dirichlet data on the whole boundary (no natural condition involved) is solved equally
// well by both forms, with the same variational wall force.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "coapt/core/context.hpp"
#include "coapt/fem/assembly.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fluid/kernels.hpp"
#include "coapt/fluid/navier_stokes.hpp"
#include "coapt/mesh/distribute.hpp"
#include "coapt/mesh/generators.hpp"

namespace {

using coapt::fluid::ElementData;
using coapt::fluid::ViscousForm;

/// A distorted triangle with Stokes data and no stabilisation (τ = 0): the residual is the
/// Galerkin part μ-term − p∇·w + q∇·u only.
ElementData<2> galerkin_triangle(ViscousForm form, double viscosity) {
  ElementData<2> data;
  double e[2][2] = {{0.31, 0.04}, {-0.07, 0.27}};
  const double det = coapt::fem::detail::gradients_from_edges<2>(e, data.gradients);
  data.measure = std::abs(det) / 2;
  data.viscosity = viscosity;
  data.convection = false;
  data.viscous_form = form;
  return data;
}

/// Nodal unknowns of u = A x (zero pressure) at the triangle's vertices 0, e_1, e_2 above.
void linear_velocity(const double (&A)[2][2], double (&x)[9]) {
  const double points[3][2] = {{0, 0}, {0.31, 0.04}, {-0.07, 0.27}};
  for (int a = 0; a < 3; ++a) {
    for (int i = 0; i < 2; ++i) x[a * 3 + i] = A[i][0] * points[a][0] + A[i][1] * points[a][1];
    x[a * 3 + 2] = 0.0;
  }
}

TEST(FluidViscousForm, LinearVelocityGivesTheClosedFormResidual) {
  // u = A x has ∇u = A: Laplace r_(a,i) = μ|T| Σ_j ∂_jλ_a A_ij, stress adds μ|T| Σ_j ∂_jλ_a A_ji.
  const double mu = 0.37;
  const double A[2][2] = {{0.5, 1.7}, {-0.4, -0.5}};  // trace-free: no continuity residual
  double x[9];
  linear_velocity(A, x);
  for (ViscousForm form : {ViscousForm::laplace, ViscousForm::stress}) {
    const auto data = galerkin_triangle(form, mu);
    double r[9];
    coapt::fluid::element_residual<2, double>(data, x, r);
    for (int a = 0; a < 3; ++a) {
      for (int i = 0; i < 2; ++i) {
        double expected = 0;
        for (int j = 0; j < 2; ++j) {
          expected += data.gradients[a][j] * A[i][j];
          if (form == ViscousForm::stress) expected += data.gradients[a][j] * A[j][i];
        }
        expected *= mu * data.measure;
        EXPECT_NEAR(r[a * 3 + i], expected, 1e-15) << "vertex " << a << " component " << i;
      }
      EXPECT_NEAR(r[a * 3 + 2], 0.0, 1e-15);
    }
  }
}

TEST(FluidViscousForm, RigidRotationHasNoViscousStressInTheStressFormOnly) {
  // u = ω × x: ε(u) = 0, so the stress form's viscous residual vanishes; the Laplace form's
  // ∇u = [[0, −ω], [ω, 0]] does not.
  const double A[2][2] = {{0.0, -2.0}, {2.0, 0.0}};
  double x[9];
  linear_velocity(A, x);
  double largest[2] = {0, 0};
  for (ViscousForm form : {ViscousForm::laplace, ViscousForm::stress}) {
    const auto data = galerkin_triangle(form, 1.0);
    double r[9];
    coapt::fluid::element_residual<2, double>(data, x, r);
    for (int k = 0; k < 9; ++k)
      largest[form == ViscousForm::stress] =
          std::max(largest[form == ViscousForm::stress], std::abs(r[k]));
  }
  EXPECT_GT(largest[0], 0.1);
  EXPECT_LT(largest[1], 1e-15);
}

template <int Dim>
void check_stress_jacobian() {
  constexpr int m = (Dim + 1) * (Dim + 1);
  std::mt19937 random(7 + Dim);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double e[Dim][Dim];
  for (int k = 0; k < Dim; ++k)
    for (int i = 0; i < Dim; ++i) e[k][i] = (k == i ? 0.3 : 0.0) + 0.08 * uniform(random);
  ElementData<Dim> data;
  const double det = coapt::fem::detail::gradients_from_edges<Dim>(e, data.gradients);
  data.measure = std::abs(det) / coapt::fem::detail::factorial(Dim);
  data.density = 1.1;
  data.viscosity = 0.05;
  data.viscous_form = ViscousForm::stress;
  data.mass_coefficient = 1.5 / 0.01;
  for (int a = 0; a <= Dim; ++a)
    for (int i = 0; i < Dim; ++i) data.history[a][i] = 20 * uniform(random);
  double x[m];
  for (double& value : x) value = uniform(random);
  double u[Dim];
  for (int i = 0; i < Dim; ++i) u[i] = x[i];
  coapt::fluid::set_stabilisation<Dim>(data, u, 0.01, 9.0);
  double r[m], K[m * m];
  coapt::fluid::element_residual_and_jacobian<Dim>(data, x, r, K);
  double scale = 0;
  for (double value : K) scale = std::max(scale, std::abs(value));
  const double step = 1e-6;
  for (int col = 0; col < m; ++col) {
    double plus[m], minus[m], r_plus[m], r_minus[m];
    std::copy(x, x + m, plus);
    std::copy(x, x + m, minus);
    plus[col] += step;
    minus[col] -= step;
    coapt::fluid::element_residual<Dim, double>(data, plus, r_plus);
    coapt::fluid::element_residual<Dim, double>(data, minus, r_minus);
    for (int row = 0; row < m; ++row)
      EXPECT_NEAR(K[row * m + col], (r_plus[row] - r_minus[row]) / (2 * step), 1e-7 * scale)
          << "row " << row << " col " << col;
  }
}

TEST(FluidViscousForm, StressJacobianMatchesFiniteDifferences) {
  check_stress_jacobian<2>();
  check_stress_jacobian<3>();
}

// Poiseuille u = 4y(1 − y), p = 8μ(4 − x) on [0, 4] × [0, 1] with the exact velocity on the
// whole boundary and p fixed at one outlet vertex. The exact solution is the same for both forms
// (∇·u = 0), and no natural condition enters, so both must reproduce it equally well.
struct Channel {
  double velocity_error = 0;  ///< max over vertices |u_h − u| (peak 1)
  std::vector<double> bottom_force;
};

Channel solve_channel(ViscousForm form) {
  constexpr double length = 4.0, mu = 0.5;
  coapt::mesh::Mesh whole;
  if (coapt::rank_of(MPI_COMM_WORLD) == 0)
    whole = coapt::mesh::structured_rectangle(0, 0, length, 1, 32, 8);
  const auto mesh = coapt::mesh::distribute(whole, MPI_COMM_WORLD);
  coapt::fluid::FluidParameters parameters;
  parameters.viscosity = mu;
  parameters.viscous_form = form;
  coapt::fluid::NavierStokes fluid(mesh, parameters);
  const int n = 3;
  std::vector<PetscInt> dofs;
  for (int v = 0; v < mesh.n_owned_vertices; ++v) {
    const double x = mesh.point(v)[0], y = mesh.point(v)[1];
    const bool boundary = x < 1e-12 || x > length - 1e-12 || y < 1e-12 || y > 1 - 1e-12;
    if (!boundary) continue;
    const PetscInt base = mesh.global_vertex[v] * n;
    VecSetValue(fluid.state(), base, 4 * y * (1 - y), INSERT_VALUES);
    dofs.push_back(base);
    dofs.push_back(base + 1);
    if (x > length - 1e-12 && std::abs(y - 0.5) < 1e-12) dofs.push_back(base + 2);  // p = 0
  }
  VecAssemblyBegin(fluid.state());
  VecAssemblyEnd(fluid.state());
  coapt::fem::update_ghosts(fluid.state());
  fluid.set_dirichlet_dofs(dofs);
  const coapt::fluid::TimeLevel steady;
  fluid.solve(steady, "channel");
  Channel result;
  {
    coapt::fem::LocalValues state(fluid.state());
    for (int v = 0; v < mesh.n_owned_vertices; ++v) {
      const double y = mesh.point(v)[1];
      const std::size_t base = static_cast<std::size_t>(v) * n;
      result.velocity_error =
          std::max({result.velocity_error, std::abs(state[base] - 4 * y * (1 - y)),
                    std::abs(state[base + 1])});
    }
  }
  MPI_Allreduce(MPI_IN_PLACE, &result.velocity_error, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  result.bottom_force = fluid.boundary_force(3, steady);  // tag 3: y = 0
  return result;
}

TEST(FluidViscousForm, DirichletPoiseuilleIsTheSameInBothForms) {
  const auto laplace = solve_channel(ViscousForm::laplace);
  const auto stress = solve_channel(ViscousForm::stress);
  // Both near the exact profile on 8 cells across, with errors within 5 % of each other.
  EXPECT_LT(laplace.velocity_error, 0.02);
  EXPECT_LT(stress.velocity_error, 0.02);
  EXPECT_LT(std::abs(stress.velocity_error - laplace.velocity_error),
            0.05 * laplace.velocity_error);
  // The variational force on the bottom wall: its x-component (the wall shear μ ∂_y u = 2 times
  // the P1 indicator, about 7 N/m) agrees between the forms to 0.1 %; the y-component (the
  // pressure) to 1 % (the forms differ by ∫ μ ∇χ·(∇u)ᵀ over the cells at the wall, nonzero for
  // the discrete u_h).
  ASSERT_EQ(laplace.bottom_force.size(), 2u);
  ASSERT_EQ(stress.bottom_force.size(), 2u);
  EXPECT_NEAR(stress.bottom_force[0], laplace.bottom_force[0],
              1e-3 * std::abs(laplace.bottom_force[0]));
  EXPECT_NEAR(stress.bottom_force[1], laplace.bottom_force[1],
              1e-2 * std::abs(laplace.bottom_force[1]));
  std::printf(
      "bottom wall force: laplace (%.6f, %.6f), stress (%.6f, %.6f); velocity error "
      "%.6e / %.6e\n",
      laplace.bottom_force[0], laplace.bottom_force[1], stress.bottom_force[0],
      stress.bottom_force[1], laplace.velocity_error, stress.velocity_error);
}

}  // namespace
