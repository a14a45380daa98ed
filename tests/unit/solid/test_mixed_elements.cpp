// The mixed displacement-pressure P1-P1 element: its tangent is the derivative of its
// residual (central differences, 2D and 3D, both nearly incompressible laws, with a pressure
// field), it is symmetric, and at u = 0, p = 0 the residual vanishes.
#include <gtest/gtest.h>

#include <cmath>

#include "coapt/fem/p1.hpp"
#include "coapt/solid/mixed_elements.hpp"
#include "element_test_support.hpp"

namespace coapt::solid {
namespace {

std::vector<Material> laws() {
  FibreReinforced fibre;
  fibre.shear_modulus = 1.0e5;
  fibre.bulk_modulus = 5.0e6;
  fibre.fibre_k1 = 2.0e5;
  fibre.fibre_k2 = 3.0;
  fibre.n_fibre_families = 2;
  // κ/μ = 50: P_iso = P − P_vol cancels O(κ) terms, which would leave the central
  // differences (not the tangent) with round-off of order ε κ/step at κ/μ = 5000.
  return {NearlyIncompressibleNeoHookean{1.0e5, 5.0e6}, fibre};
}

FibreDirections fibres() {
  return testing::two_fibre_families();
}

using testing::reference_cell;

template <int Dim>
MixedNodalValues<Dim> some_state() {
  MixedNodalValues<Dim> w;
  for (int a = 0; a <= Dim; ++a) {
    for (int i = 0; i < Dim; ++i) w(a, i) = 0.04 * std::sin(1.0 + 2.0 * a + 3.1 * i) + 0.06 * a;
    w(a, Dim) = 3.0e4 * std::cos(0.7 * a);  // Pa
  }
  return w;
}

template <int Dim>
void check(const Material& material) {
  const auto points = reference_cell<Dim>();
  const auto g = fem::p1_geometry<Dim>(points);
  const double h = longest_edge<Dim>(points);
  const auto w = some_state<Dim>();
  MixedElementVector<Dim> r;
  MixedElementMatrix<Dim> K;
  ASSERT_GT(mixed_element<Dim>(g, h, material, fibres(), w, r, &K), 0.0);
  constexpr int m = Dim + 1;
  MixedElementMatrix<Dim> difference;
  for (int b = 0; b <= Dim; ++b)
    for (int k = 0; k <= Dim; ++k) {
      const double step = k == Dim ? 1.0 : 1e-6;  // p is in Pa, u in m
      auto plus = w, minus = w;
      plus(b, k) += step;
      minus(b, k) -= step;
      MixedElementVector<Dim> r_plus, r_minus;
      mixed_element<Dim>(g, h, material, fibres(), plus, r_plus, nullptr);
      mixed_element<Dim>(g, h, material, fibres(), minus, r_minus, nullptr);
      difference.col(b * m + k) = (r_plus - r_minus) / (2.0 * step);
    }
  // Compare block by block (the blocks have different units).
  for (int a = 0; a <= Dim; ++a)
    for (int b = 0; b <= Dim; ++b)
      for (int i = 0; i <= Dim; ++i)
        for (int k = 0; k <= Dim; ++k) {
          const bool row_p = i == Dim, column_p = k == Dim;
          double scale = 0;
          for (int c = 0; c < K.rows(); ++c)
            for (int d = 0; d < K.cols(); ++d)
              if ((c % m == Dim) == row_p && (d % m == Dim) == column_p)
                scale = std::max(scale, std::abs(K(c, d)));
          EXPECT_NEAR(K(a * m + i, b * m + k), difference(a * m + i, b * m + k), 1e-6 * scale)
              << a << i << b << k;
        }
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-9 * K.cwiseAbs().maxCoeff());
  // The reference state with zero pressure is an equilibrium.
  ASSERT_GT(mixed_element<Dim>(g, h, material, fibres(), MixedNodalValues<Dim>::Zero(), r, nullptr),
            0.0);
  EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(MixedElement, TangentIsTheDerivativeOfTheResidual2D) {
  for (const auto& law : laws()) check<2>(law);
}
TEST(MixedElement, TangentIsTheDerivativeOfTheResidual3D) {
  for (const auto& law : laws()) check<3>(law);
}

}  // namespace
}  // namespace coapt::solid
