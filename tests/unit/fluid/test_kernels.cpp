// Element kernels of the fluid: BDF weights, the stabilisation parameters' limits, and the
// Jacobian against central finite differences of the residual (τ frozen) and against
// forward-mode differentiation of it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "coapt/fem/p1.hpp"
#include "coapt/fluid/kernels.hpp"

namespace {

using coapt::fluid::ElementData;

TEST(FluidKernels, BdfWeightsDifferentiateQuadraticsExactly) {
  // u = t² on t_{n−1} = 0, t_n = 1, t_{n+1} = 1 + ω: u̇(t_{n+1}) = 2(1 + ω) exactly for BDF2.
  for (double omega : {1.0, 0.5, 2.0, 0.3}) {
    const auto a = coapt::fluid::bdf_weights(2, omega);
    const double t = 1 + omega;
    const double derivative = (a[0] * t * t + a[1] * 1.0 + a[2] * 0.0) / omega;
    EXPECT_NEAR(derivative, 2 * t, 1e-13) << "omega " << omega;
    EXPECT_NEAR(a[0] + a[1] + a[2], 0.0, 1e-14);  // constants have no derivative
  }
  const auto uniform = coapt::fluid::bdf_weights(2, 1.0);
  EXPECT_DOUBLE_EQ(uniform[0], 1.5);
  EXPECT_DOUBLE_EQ(uniform[1], -2.0);
  EXPECT_DOUBLE_EQ(uniform[2], 0.5);
  const auto euler = coapt::fluid::bdf_weights(1, 3.0);
  EXPECT_DOUBLE_EQ(euler[0], 1.0);
  EXPECT_DOUBLE_EQ(euler[1], -1.0);
}

template <int Dim>
ElementData<Dim> right_simplex(double h) {
  ElementData<Dim> data;
  double e[Dim][Dim] = {};
  for (int k = 0; k < Dim; ++k) e[k][k] = h;
  const double det = coapt::fem::detail::gradients_from_edges<Dim>(e, data.gradients);
  data.measure = std::abs(det) / coapt::fem::detail::factorial(Dim);
  return data;
}

TEST(FluidKernels, StabilisationLimits) {
  // Right triangle with legs h: G = 4/h² I. Advection-dominated: τ_M → h/(2|u|); steady
  // Stokes-like: τ_M = 1/(√C_I ν |G|_F) = h²/(4√(2 C_I) ν); τ_C = 1/(τ_M tr G).
  const double h = 0.1;
  auto data = right_simplex<2>(h);
  data.density = 2.0;
  data.viscosity = 2e-9;  // ν = 1e-9
  const double u[2] = {3.0, 0.0};
  coapt::fluid::set_stabilisation<2>(data, u, 0.0, 9.0);
  EXPECT_NEAR(data.tau_m, h / (2 * 3.0), 1e-9);
  EXPECT_NEAR(data.tau_c, 1.0 / (data.tau_m * 8.0 / (h * h)), 1e-15);
  data.viscosity = 2.0;  // ν = 1, u negligible
  const double still[2] = {0.0, 0.0};
  coapt::fluid::set_stabilisation<2>(data, still, 0.0, 9.0);
  EXPECT_NEAR(data.tau_m, h * h / (4 * std::sqrt(2 * 9.0) * 1.0), 1e-15);
  // A short time step dominates: τ_M → Δt/2.
  data.viscosity = 2e-12;
  coapt::fluid::set_stabilisation<2>(data, still, 1e-6, 9.0);
  EXPECT_NEAR(data.tau_m, 0.5e-6, 1e-12);
}

template <int Dim>
void check_jacobian(bool transient, bool convection) {
  constexpr int m = (Dim + 1) * (Dim + 1);
  std::mt19937 random(42 + Dim);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  // A distorted simplex.
  double e[Dim][Dim];
  for (int k = 0; k < Dim; ++k)
    for (int i = 0; i < Dim; ++i) e[k][i] = (k == i ? 0.3 : 0.0) + 0.08 * uniform(random);
  ElementData<Dim> data;
  const double det = coapt::fem::detail::gradients_from_edges<Dim>(e, data.gradients);
  data.measure = std::abs(det) / coapt::fem::detail::factorial(Dim);
  data.density = 1.3;
  data.viscosity = 0.02;
  data.convection = convection;
  if (transient) {
    data.mass_coefficient = 1.5 / 0.01;
    for (int a = 0; a <= Dim; ++a)
      for (int i = 0; i < Dim; ++i) data.history[a][i] = 50 * uniform(random);
  }
  double x[m];
  for (double& value : x) value = uniform(random);
  double u[Dim];  // τ from vertex 0's velocity (any frozen value will do)
  for (int i = 0; i < Dim; ++i) u[i] = x[i];
  coapt::fluid::set_stabilisation<Dim>(data, u, transient ? 0.01 : 0.0, 9.0);

  double r[m], K[m * m];
  coapt::fluid::element_residual_and_jacobian<Dim>(data, x, r, K);
  double r_plain[m];
  coapt::fluid::element_residual<Dim, double>(data, x, r_plain);
  for (int k = 0; k < m; ++k) EXPECT_NEAR(r[k], r_plain[k], 1e-14 * (1 + std::abs(r[k])));

  const double step = 1e-6;
  double scale = 0;
  for (double value : K) scale = std::max(scale, std::abs(value));
  for (int col = 0; col < m; ++col) {
    double plus[m], minus[m], r_plus[m], r_minus[m];
    std::copy(x, x + m, plus);
    std::copy(x, x + m, minus);
    plus[col] += step;
    minus[col] -= step;
    coapt::fluid::element_residual<Dim, double>(data, plus, r_plus);
    coapt::fluid::element_residual<Dim, double>(data, minus, r_minus);
    for (int row = 0; row < m; ++row) {
      const double difference = (r_plus[row] - r_minus[row]) / (2 * step);
      EXPECT_NEAR(K[row * m + col], difference, 1e-7 * scale) << "row " << row << " col " << col;
    }
  }
}

TEST(FluidKernels, JacobianMatchesFiniteDifferences2D) {
  check_jacobian<2>(false, true);
  check_jacobian<2>(true, true);
  check_jacobian<2>(true, false);
}

TEST(FluidKernels, JacobianMatchesFiniteDifferences3D) {
  check_jacobian<3>(false, true);
  check_jacobian<3>(true, true);
}

// The written-out Jacobian is the derivative of the residual to round-off: it matches the
// forward-mode one in every combination of dimension, time term, convection and viscous form.
template <int Dim>
void check_against_differentiation(bool transient, bool convection,
                                   coapt::fluid::ViscousForm form) {
  constexpr int m = (Dim + 1) * (Dim + 1);
  std::mt19937 random(7 + Dim);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double e[Dim][Dim];
  for (int k = 0; k < Dim; ++k)
    for (int i = 0; i < Dim; ++i) e[k][i] = (k == i ? 0.2 : 0.0) + 0.06 * uniform(random);
  ElementData<Dim> data;
  const double det = coapt::fem::detail::gradients_from_edges<Dim>(e, data.gradients);
  data.measure = std::abs(det) / coapt::fem::detail::factorial(Dim);
  data.density = 1.1;
  data.viscosity = 0.03;
  data.convection = convection;
  data.viscous_form = form;
  if (transient) {
    data.mass_coefficient = 1.5 / 0.02;
    for (int a = 0; a <= Dim; ++a)
      for (int i = 0; i < Dim; ++i) data.history[a][i] = 20 * uniform(random);
  }
  double x[m];
  for (double& value : x) value = uniform(random);
  double u[Dim];
  for (int i = 0; i < Dim; ++i) u[i] = 0.5 * x[Dim + 1 + i];
  coapt::fluid::set_stabilisation<Dim>(data, u, transient ? 0.02 : 0.0, 9.0);
  double r[m], K[m * m], r_reference[m], K_reference[m * m];
  coapt::fluid::element_residual_and_jacobian<Dim>(data, x, r, K);
  coapt::fluid::element_residual_and_jacobian_by_differentiation<Dim>(data, x, r_reference,
                                                                      K_reference);
  double scale = 0;
  for (double value : K_reference) scale = std::max(scale, std::abs(value));
  for (int k = 0; k < m; ++k) EXPECT_EQ(r[k], r_reference[k]);
  for (int k = 0; k < m * m; ++k)
    EXPECT_NEAR(K[k], K_reference[k], 1e-13 * scale) << "row " << k / m << " col " << k % m;
}

TEST(FluidKernels, JacobianMatchesForwardModeDifferentiation) {
  using coapt::fluid::ViscousForm;
  for (const auto form : {ViscousForm::laplace, ViscousForm::stress})
    for (const bool transient : {false, true})
      for (const bool convection : {false, true}) {
        check_against_differentiation<2>(transient, convection, form);
        check_against_differentiation<3>(transient, convection, form);
      }
}

TEST(FluidKernels, RigidMotionAndConstantPressureGiveNoViscousOrContinuityResidual) {
  // Steady Stokes (no convection) with constant velocity and constant pressure: the element
  // residuals sum to zero over the vertices for the momentum (−p∇·w sums to 0, ∇u = 0) and the
  // continuity rows are zero.
  auto data = right_simplex<3>(0.2);
  data.viscosity = 0.7;
  data.convection = false;
  const double u[3] = {0.4, -0.2, 0.1};
  coapt::fluid::set_stabilisation<3>(data, u, 0.0, 9.0);
  double x[16], r[16];
  for (int a = 0; a < 4; ++a) {
    for (int i = 0; i < 3; ++i) x[a * 4 + i] = u[i];
    x[a * 4 + 3] = 5.0;
  }
  coapt::fluid::element_residual<3, double>(data, x, r);
  for (int i = 0; i < 3; ++i) {
    double sum = 0;
    for (int a = 0; a < 4; ++a) sum += r[a * 4 + i];
    EXPECT_NEAR(sum, 0.0, 1e-14);
  }
  for (int a = 0; a < 4; ++a) EXPECT_NEAR(r[a * 4 + 3], 0.0, 1e-14);
}

}  // namespace
