// P1 geometry, barycentric basis, dual basis and reference map.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>

#include "coapt/core/error.hpp"
#include "coapt/fem/p1.hpp"
#include "coapt/fem/quadrature.hpp"

namespace {

using namespace coapt::fem;

template <int Dim>
using Vertices = Eigen::Matrix<double, Dim + 1, Dim>;

/// A random simplex with vertices in [-1, 1]^Dim, reasonably shaped (not nearly flat).
template <int Dim>
Vertices<Dim> random_simplex(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  while (true) {
    Vertices<Dim> v;
    for (int a = 0; a <= Dim; ++a)
      for (int i = 0; i < Dim; ++i) v(a, i) = u(rng);
    const Eigen::Matrix<double, Dim, Dim> J = (v.bottomRows(Dim).rowwise() - v.row(0)).transpose();
    if (std::abs(J.determinant()) > 0.05 * std::pow(0.5, Dim)) return v;
  }
}

template <int Dim>
Vertices<Dim> reference_simplex() {
  Vertices<Dim> v = Vertices<Dim>::Zero();
  v.bottomRows(Dim).setIdentity();
  return v;
}

template <int Dim>
void check_gradients(const Vertices<Dim>& v) {
  const P1Geometry<Dim> g = p1_geometry(v);
  const double scale = g.gradients.cwiseAbs().maxCoeff();
  // Σ_a ∇λ_a = 0.
  EXPECT_LE(g.gradients.colwise().sum().cwiseAbs().maxCoeff(), 1e-14 * scale);
  // ∇λ_a·(x_b − x_0) = λ_a(x_b) − λ_a(x_0) = δ_ab − δ_a0.
  for (int a = 0; a <= Dim; ++a)
    for (int b = 0; b <= Dim; ++b) {
      const double expected = (a == b ? 1.0 : 0.0) - (a == 0 ? 1.0 : 0.0);
      const double value = g.gradients.row(a).dot(v.row(b) - v.row(0));
      EXPECT_NEAR(value, expected, 1e-13) << "a " << a << " b " << b;
    }
  // Jacobian columns are the edges; gradients agree with a pivoted LU inverse.
  for (int k = 0; k < Dim; ++k)
    EXPECT_LE((g.jacobian.col(k) - (v.row(k + 1) - v.row(0)).transpose()).norm(), 0.0);
  const Eigen::Matrix<double, Dim, Dim> inverse = Eigen::MatrixXd(g.jacobian).fullPivLu().inverse();
  EXPECT_LE((g.gradients.bottomRows(Dim) - inverse).cwiseAbs().maxCoeff(), 1e-13 * scale);
  // Measures.
  // (det J cancels: its attainable accuracy is relative to the product of the edge lengths.)
  const double factorial = Dim == 3 ? 6.0 : Dim;
  EXPECT_NEAR(g.signed_measure, g.jacobian.determinant() / factorial,
              1e-15 * g.jacobian.colwise().norm().prod() / factorial);
  EXPECT_DOUBLE_EQ(g.measure, std::abs(g.signed_measure));
  // The fast pointer path gives the same geometry.
  const double* p[Dim + 1];
  double rows[Dim + 1][Dim];
  for (int a = 0; a <= Dim; ++a) {
    for (int i = 0; i < Dim; ++i) rows[a][i] = v(a, i);
    p[a] = rows[a];
  }
  const P1Geometry<Dim> h = p1_geometry<Dim>(p);
  EXPECT_EQ(h.gradients, g.gradients);
  EXPECT_EQ(h.signed_measure, g.signed_measure);
  EXPECT_EQ(p1_signed_measure<Dim>(p), g.signed_measure);
}

TEST(P1Geometry, GradientsOnRandomSimplices) {
  std::mt19937_64 rng(12345);
  for (int trial = 0; trial < 200; ++trial) {
    check_gradients<1>(random_simplex<1>(rng));
    check_gradients<2>(random_simplex<2>(rng));
    check_gradients<3>(random_simplex<3>(rng));
  }
}

TEST(P1Geometry, MeasuresOfKnownSimplices) {
  EXPECT_DOUBLE_EQ(p1_geometry(reference_simplex<1>()).measure, 1.0);
  EXPECT_DOUBLE_EQ(p1_geometry(reference_simplex<2>()).measure, 0.5);
  EXPECT_DOUBLE_EQ(p1_geometry(reference_simplex<3>()).measure, 1.0 / 6.0);

  // Segment [3, -2]: length 5, negative orientation.
  Vertices<1> segment;
  segment << 3, -2;
  EXPECT_DOUBLE_EQ(p1_geometry(segment).measure, 5.0);
  EXPECT_DOUBLE_EQ(p1_geometry(segment).signed_measure, -5.0);

  // Equilateral triangle of side 2: √3; swapping two vertices flips the sign.
  Vertices<2> triangle;
  triangle << 0, 0, 2, 0, 1, std::sqrt(3.0);
  EXPECT_NEAR(p1_geometry(triangle).signed_measure, std::sqrt(3.0), 1e-15);
  triangle.row(1).swap(triangle.row(2));
  EXPECT_NEAR(p1_geometry(triangle).signed_measure, -std::sqrt(3.0), 1e-15);

  // Regular tetrahedron of side a = 2√2 (alternate cube corners): a³/(6√2) = 8/3.
  Vertices<3> tet;
  tet << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
  EXPECT_NEAR(p1_geometry(tet).measure, 8.0 / 3.0, 1e-14);
  // Box corner tetrahedron with edges 2, 3, 5 along the axes, translated: 30/6.
  tet << 10, 20, 30, 12, 20, 30, 10, 23, 30, 10, 20, 35;
  EXPECT_NEAR(p1_geometry(tet).signed_measure, 5.0, 1e-12);
  // Scaling by s multiplies the measure by s^3.
  EXPECT_NEAR(p1_geometry(Vertices<3>(1e-3 * tet)).measure, 5e-9, 1e-21);
}

TEST(P1Geometry, DegenerateSimplexThrows) {
  Vertices<2> flat;
  flat << 0, 0, 1, 1, 2, 2;
  EXPECT_THROW(p1_geometry(flat), coapt::InputError);
  Vertices<3> coplanar;
  coplanar << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0;
  try {
    p1_geometry(coplanar);
    FAIL() << "no exception";
  } catch (const coapt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("degenerate"), std::string::npos) << e.what();
  }
  Vertices<3> nan_tet = reference_simplex<3>();
  nan_tet(2, 1) = std::nan("");
  EXPECT_THROW(p1_geometry(nan_tet), coapt::InputError);
}

template <int Dim>
void check_basis(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // λ at the reference vertices is the identity; Σλ = 1; Σψ = 1; ψ = (Dim+2)λ − 1.
  const Vertices<Dim> ref = reference_simplex<Dim>();
  for (int b = 0; b <= Dim; ++b) {
    const Eigen::Matrix<double, Dim, 1> xi = ref.row(b).transpose();
    const auto lambda = p1_values<Dim>(xi);
    for (int a = 0; a <= Dim; ++a) EXPECT_EQ(lambda(a), a == b ? 1.0 : 0.0);
  }
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::Matrix<double, Dim, 1> xi;
    for (int i = 0; i < Dim; ++i) xi(i) = u(rng) / Dim;
    EXPECT_NEAR(p1_values<Dim>(xi).sum(), 1.0, 1e-15);
    EXPECT_NEAR(p1_dual_values<Dim>(xi).sum(), 1.0, 1e-14);
    EXPECT_LE(((Dim + 2) * p1_values<Dim>(xi).array() - 1 - p1_dual_values<Dim>(xi).array())
                  .abs()
                  .maxCoeff(),
              1e-15);
    // The map sends xi to Σ λ_a x_a, and the gradients recover λ from the physical point.
    const Vertices<Dim> v = random_simplex<Dim>(rng);
    const auto x = map_to_physical<Dim>(v, xi);
    const P1Geometry<Dim> g = p1_geometry(v);
    const Eigen::Matrix<double, Dim + 1, 1> lambda = p1_values<Dim>(xi);
    EXPECT_LE((x - (lambda.transpose() * v).transpose()).norm(), 1e-15);
    const Eigen::Matrix<double, Dim + 1, 1> recovered =
        (g.gradients * (x - v.row(0).transpose())) + Eigen::Matrix<double, Dim + 1, 1>::UnitX();
    EXPECT_LE((recovered - lambda).cwiseAbs().maxCoeff(), 1e-13);
  }
}

TEST(P1Basis, ValuesDualValuesAndMap) {
  std::mt19937_64 rng(7);
  check_basis<1>(rng);
  check_basis<2>(rng);
  check_basis<3>(rng);
}

template <int Dim>
void check_biorthogonality(std::mt19937_64& rng) {
  const QuadratureRule& rule = simplex_quadrature(Dim, 2);
  for (int trial = 0; trial < 20; ++trial) {
    const P1Geometry<Dim> g = p1_geometry(random_simplex<Dim>(rng));
    const double jacobian = g.measure / reference_simplex_measure(Dim);
    Eigen::Matrix<double, Dim + 1, Dim + 1> psi_lambda =
        Eigen::Matrix<double, Dim + 1, Dim + 1>::Zero();
    Eigen::Matrix<double, Dim + 1, 1> lambda_integral = Eigen::Matrix<double, Dim + 1, 1>::Zero();
    for (int q = 0; q < rule.size(); ++q) {
      const Eigen::Map<const Eigen::Matrix<double, Dim, 1>> xi(rule.point(q));
      const auto lambda = p1_values<Dim>(xi);
      const auto psi = p1_dual_values<Dim>(xi);
      psi_lambda += rule.weights[q] * jacobian * psi * lambda.transpose();
      lambda_integral += rule.weights[q] * jacobian * lambda;
    }
    // ∫ψ_aλ_b = δ_ab ∫λ_b, and ∫λ_b = |T|/(Dim+1).
    for (int b = 0; b <= Dim; ++b)
      EXPECT_NEAR(lambda_integral(b), g.measure / (Dim + 1), 1e-14 * g.measure);
    for (int a = 0; a <= Dim; ++a)
      for (int b = 0; b <= Dim; ++b)
        EXPECT_NEAR(psi_lambda(a, b), a == b ? lambda_integral(b) : 0.0, 1e-14 * g.measure)
            << "a " << a << " b " << b;
  }
}

TEST(P1Basis, DualBasisIsBiorthogonal) {
  std::mt19937_64 rng(99);
  check_biorthogonality<1>(rng);
  check_biorthogonality<2>(rng);
  check_biorthogonality<3>(rng);
}

}  // namespace
