// Total-Lagrangian P1 element kernels: tangent = derivative of the residual (central
// differences, every material, 2D and 3D), agreement with the small-strain stiffness at
// u = 0, patch tests (a homogeneous deformation gives the element forces of a uniform
// stress: zero at interior nodes of an assembled patch) and rigid rotations (no force for
// the objective laws).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "coapt/fem/kernels.hpp"
#include "coapt/solid/elements.hpp"
#include "element_test_support.hpp"

namespace coapt::solid {
namespace {

std::vector<Material> all_materials() {
  FibreReinforced fibre;
  fibre.shear_modulus = 1.0e5;
  fibre.bulk_modulus = 5.0e5;
  fibre.fibre_k1 = 2.0e5;
  fibre.fibre_k2 = 3.0;
  fibre.n_fibre_families = 2;
  return {LinearElastic::from_young_poisson(2.0e5, 0.3),
          SaintVenantKirchhoff::from_young_poisson(2.0e5, 0.3),
          NeoHookean::from_young_poisson(2.0e5, 0.3),
          NearlyIncompressibleNeoHookean::from_young_poisson(2.0e5, 0.45), fibre};
}

FibreDirections fibres() {
  return testing::two_fibre_families();
}

using testing::reference_cell;

// A moderately large displacement (|H| ~ 0.2): fibres stretched, J ≠ 1.
template <int Dim>
NodalValues<Dim> some_displacement() {
  NodalValues<Dim> u;
  for (int a = 0; a <= Dim; ++a)
    for (int i = 0; i < Dim; ++i) u(a, i) = 0.05 * std::sin(1.0 + 2.0 * a + 3.1 * i) + 0.08 * a;
  return u;
}

template <int Dim>
void check_tangent_against_differences() {
  const auto g = fem::p1_geometry<Dim>(reference_cell<Dim>());
  const NodalValues<Dim> u = some_displacement<Dim>();
  for (const Material& material : all_materials()) {
    const auto K = element_tangent<Dim>(g, material, fibres(), u);
    const double h = 1e-6;
    double worst = 0;
    for (int b = 0; b <= Dim; ++b)
      for (int k = 0; k < Dim; ++k) {
        NodalValues<Dim> plus = u, minus = u;
        plus(b, k) += h;
        minus(b, k) -= h;
        const ElementVector<Dim> r_plus = element_residual<Dim>(g, material, fibres(), plus);
        const ElementVector<Dim> r_minus = element_residual<Dim>(g, material, fibres(), minus);
        const ElementVector<Dim> difference = (r_plus - r_minus) / (2 * h);
        worst = std::max(worst, (K.col(b * Dim + k) - difference).norm() / K.norm());
      }
    // Central differences: error O(h²) ~ 1e-12 relative plus round-off ~ ε/h ~ 1e-10.
    EXPECT_LT(worst, 1e-7) << name(material) << " in " << Dim << "D";
  }
}

TEST(SolidElements, TangentIsTheDerivativeOfTheResidual2D) {
  check_tangent_against_differences<2>();
}
TEST(SolidElements, TangentIsTheDerivativeOfTheResidual3D) {
  check_tangent_against_differences<3>();
}

template <int Dim>
void check_small_strain_limit() {
  const auto g = fem::p1_geometry<Dim>(reference_cell<Dim>());
  const double lambda = 1.3e5, mu = 0.7e5;
  const auto expected = fem::element_elasticity<Dim>(g, lambda, mu);
  for (const Material& material :
       {Material(LinearElastic{lambda, mu}), Material(SaintVenantKirchhoff{lambda, mu}),
        Material(NeoHookean{lambda, mu}),
        Material(NearlyIncompressibleNeoHookean{mu, lambda + 2.0 / 3.0 * mu})}) {
    const auto K = element_tangent<Dim>(g, material, {}, NodalValues<Dim>::Zero());
    EXPECT_LT((K - expected).norm(), 1e-10 * expected.norm()) << name(material);
  }
}

TEST(SolidElements, TangentAtRestIsTheSmallStrainStiffness2D) {
  check_small_strain_limit<2>();
}
TEST(SolidElements, TangentAtRestIsTheSmallStrainStiffness3D) {
  check_small_strain_limit<3>();
}

// Patch test: a patch of cells around an interior vertex under u = (F − I) X. F is the same
// in every cell, so the internal forces at the interior vertex cancel exactly and each cell's
// forces equal |T| P ∇N_a for the exact P(F).
template <int Dim>
void check_patch() {
  // Interior vertex 0 at the centre of a simplex star: vertices of a box around it.
  std::vector<Eigen::Matrix<double, Dim, 1>> points;
  points.push_back(Eigen::Matrix<double, Dim, 1>::Constant(0.05));
  std::vector<std::vector<int>> cells;
  if constexpr (Dim == 2) {
    points.push_back({1.0, 0.1});
    points.push_back({0.2, 1.0});
    points.push_back({-1.0, 0.3});
    points.push_back({-0.1, -1.0});
    points.push_back({0.8, -0.7});
    cells = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 1}};
  } else {
    // Octahedron around the vertex, slightly perturbed: 8 tetrahedra.
    points.push_back({1.0, 0.1, 0.0});
    points.push_back({-1.0, 0.0, 0.1});
    points.push_back({0.1, 1.0, 0.0});
    points.push_back({0.0, -1.0, -0.1});
    points.push_back({0.0, 0.1, 1.0});
    points.push_back({-0.1, 0.0, -1.0});
    for (int x : {1, 2})
      for (int y : {3, 4})
        for (int z : {5, 6}) cells.push_back({0, x, y, z});
  }
  MatrixD<Dim> F;
  if constexpr (Dim == 2)
    F << 1.2, 0.3, -0.1, 0.9;
  else
    F << 1.2, 0.3, 0.0, -0.1, 0.9, 0.2, 0.05, 0.0, 1.1;
  for (const Material& material : all_materials()) {
    Eigen::Matrix<double, Dim, 1> interior = Eigen::Matrix<double, Dim, 1>::Zero();
    double scale = 0;
    for (auto cell : cells) {
      NodalValues<Dim> x, u;
      for (int a = 0; a <= Dim; ++a) {
        x.row(a) = points[cell[a]].transpose();
        u.row(a) = ((F - MatrixD<Dim>::Identity()) * points[cell[a]]).transpose();
      }
      auto geometry = fem::p1_geometry<Dim>(x);
      if (geometry.signed_measure < 0) {  // orient positively
        std::swap(cell[1], cell[2]);
        x.row(1).swap(x.row(2));
        u.row(1).swap(u.row(2));
        geometry = fem::p1_geometry<Dim>(x);
      }
      EXPECT_LT((deformation_gradient<Dim>(geometry.gradients, u) - F).norm(), 1e-14);
      const auto r = element_residual<Dim>(geometry, material, fibres(), u);
      const MatrixD<Dim> P = piola_stress<Dim>(material, F, fibres());
      for (int a = 0; a <= Dim; ++a) {
        const Eigen::Matrix<double, Dim, 1> expected =
            geometry.measure * P * geometry.gradients.row(a).transpose();
        EXPECT_LT((r.template segment<Dim>(a * Dim) - expected).norm(), 1e-12 * P.norm());
      }
      interior += r.template segment<Dim>(0);
      scale += geometry.measure * P.norm();
    }
    EXPECT_LT(interior.norm(), 1e-13 * scale) << name(material);
  }
}

TEST(SolidElements, PatchTest2D) {
  check_patch<2>();
}
TEST(SolidElements, PatchTest3D) {
  check_patch<3>();
}

// A rigid rotation produces no internal force for the finite-strain laws.
TEST(SolidElements, RigidRotationIsStressFree) {
  const auto g = fem::p1_geometry<3>(reference_cell<3>());
  const double angle = 0.7;
  Matrix3 R;
  R << std::cos(angle), -std::sin(angle), 0, std::sin(angle), std::cos(angle), 0, 0, 0, 1;
  NodalValues<3> x = reference_cell<3>(), u;
  for (int a = 0; a < 4; ++a)
    u.row(a) = ((R - Matrix3::Identity()) * x.row(a).transpose()).transpose();
  const auto materials = all_materials();
  for (std::size_t m = 1; m < materials.size(); ++m) {  // [0] is the small-strain law
    const auto r = element_residual<3>(g, materials[m], fibres(), u);
    EXPECT_LT(r.norm(), 1e-9 * 2.0e5) << name(materials[m]);
  }
}

}  // namespace
}  // namespace coapt::solid
