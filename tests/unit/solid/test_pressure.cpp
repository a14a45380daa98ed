// Follower pressure on a boundary facet: the tangent is the derivative of the residual
// (central differences, 2D and 3D), the load is −p n da with n out of the cell, and over a
// closed surface the forces are p ∇V (the pressure does work p dV) with a symmetric tangent
// p ∇²V, as a conservative load must.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "coapt/solid/elements.hpp"

namespace coapt::solid {
namespace {

template <int Dim>
FacetPositions<Dim> some_facet() {
  FacetPositions<Dim> x;
  if constexpr (Dim == 2)
    x << 0.3, -0.1, 1.1, 0.4;
  else
    x << 0.1, 0.0, 0.2, 1.2, 0.3, -0.1, 0.2, 0.9, 0.4;
  return x;
}

template <int Dim>
void check_tangent() {
  const double pressure = 2.5e3, h = 1e-6;
  const FacetPositions<Dim> x = some_facet<Dim>();
  const FacetMatrix<Dim> K = pressure_facet_tangent<Dim>(x, pressure);
  double scale = 0;
  FacetMatrix<Dim> difference;
  for (int b = 0; b < Dim; ++b)
    for (int k = 0; k < Dim; ++k) {
      FacetPositions<Dim> plus = x, minus = x;
      plus(b, k) += h;
      minus(b, k) -= h;
      difference.col(b * Dim + k) = (pressure_facet_residual<Dim>(plus, pressure) -
                                     pressure_facet_residual<Dim>(minus, pressure)) /
                                    (2.0 * h);
      scale = std::max(scale, difference.col(b * Dim + k).cwiseAbs().maxCoeff());
    }
  EXPECT_GT(scale, 100.0);
  EXPECT_LT((K - difference).cwiseAbs().maxCoeff(), 1e-8 * scale) << K << "\n\n" << difference;
}

TEST(PressureLoad, TangentIsTheDerivativeOfTheResidual2D) {
  check_tangent<2>();
}
TEST(PressureLoad, TangentIsTheDerivativeOfTheResidual3D) {
  check_tangent<3>();
}

TEST(PressureLoad, LoadIsMinusPressureTimesOutwardNormal) {
  // 3D: the facet (0,0,0), (0,1,0), (1,0,0) of the unit tetrahedron, ordered with its normal
  // −z out of the cell: residual −f_ext = p n A = −p/2 z, a third per vertex.
  FacetPositions<3> x;
  x << 0, 0, 0, 0, 1, 0, 1, 0, 0;
  const auto r = pressure_facet_residual<3>(x, 6.0);
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR((r.segment<3>(3 * a) - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-15);
  // 2D: the edge (0,0) → (1,0) of the triangle (0,0), (1,0), (0,1) has the cell on its left
  // and the outward normal −y: r = p n L = −p y per unit thickness, half per vertex.
  FacetPositions<2> e;
  e << 0, 0, 1, 0;
  const auto r2 = pressure_facet_residual<2>(e, 4.0);
  EXPECT_NEAR((r2 - Eigen::Vector4d(0, -2, 0, -2)).norm(), 0.0, 1e-15);
}

double tetrahedron_volume(const Eigen::Matrix<double, 4, 3>& x) {
  Eigen::Matrix3d edges;
  for (int a = 0; a < 3; ++a) edges.col(a) = (x.row(a + 1) - x.row(0)).transpose();
  return edges.determinant() / 6.0;
}

TEST(PressureLoad, ClosedSurfaceGivesPressureTimesVolumeGradientAndSymmetricTangent) {
  Eigen::Matrix<double, 4, 3> x;
  x << 0.1, 0.0, -0.1, 1.2, 0.2, 0.0, 0.1, 1.1, 0.2, 0.2, 0.3, 0.9;
  ASSERT_GT(tetrahedron_volume(x), 0.0);
  // Faces opposite each vertex, ordered with outward normals for a positive tetrahedron.
  const int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  const double pressure = 7.0;
  Eigen::Matrix<double, 12, 1> r = Eigen::Matrix<double, 12, 1>::Zero();
  Eigen::Matrix<double, 12, 12> K = Eigen::Matrix<double, 12, 12>::Zero();
  for (const auto& face : faces) {
    FacetPositions<3> f;
    for (int a = 0; a < 3; ++a) f.row(a) = x.row(face[a]);
    const auto rf = pressure_facet_residual<3>(f, pressure);
    const auto Kf = pressure_facet_tangent<3>(f, pressure);
    for (int a = 0; a < 3; ++a) {
      r.segment<3>(3 * face[a]) += rf.segment<3>(3 * a);
      for (int b = 0; b < 3; ++b)
        K.block<3, 3>(3 * face[a], 3 * face[b]) += Kf.block<3, 3>(3 * a, 3 * b);
    }
  }
  // r = p ∂V/∂x (outward pressure: internal minus external force is p ∇V... with the sign of
  // the residual, −f_ext = p n da integrates to p ∂V/∂x_a).
  const double h = 1e-6;
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      auto plus = x, minus = x;
      plus(a, i) += h;
      minus(a, i) -= h;
      const double gradient = (tetrahedron_volume(plus) - tetrahedron_volume(minus)) / (2.0 * h);
      EXPECT_NEAR(r(3 * a + i), pressure * gradient, 1e-8) << a << " " << i;
    }
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-12 * K.cwiseAbs().maxCoeff());
  EXPECT_GT(K.cwiseAbs().maxCoeff(), 0.1);
}

}  // namespace
}  // namespace coapt::solid
