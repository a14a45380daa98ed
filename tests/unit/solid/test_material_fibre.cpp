// The fibre-reinforced (HGO-type) law against closed forms: uniaxial stretch along and
// across the fibres, fibres slack in compression, and the response to a pure volume change
// that only the full invariant I₄ (not Ī₄) gives.
//
// Closed form for F = diag(λ, t, t) and one fibre family a₀ = e₁ (derivation):
//   J = λt², I₁ = λ² + 2t², b = FFᵀ = diag(λ², t², t²), I₄ = |F a₀|² = λ².
//   Matrix, isochoric: P_iso Fᵀ = μ J^{−2/3} (FFᵀ − I₁/3 I), so
//     σ_iso = μ J^{−5/3} (b − I₁/3 I):  σ_iso,11 = 2/3 μ J^{−5/3} (λ² − t²),
//                                       σ_iso,22 = σ_iso,33 = −1/3 μ J^{−5/3} (λ² − t²).
//   Matrix, volumetric: σ_vol = κ U'(J) I = κ (J − 1/J)/2 I.
//   Fibre: P_f = 2ψ' (F a₀) ⊗ a₀, so σ_f = J⁻¹ P_f Fᵀ = (2ψ'/J) (F a₀) ⊗ (F a₀)
//     = (2/J) k₁ (λ² − 1) exp(k₂ (λ² − 1)²) λ² e₁ ⊗ e₁   for λ > 1, 0 otherwise.
// Uniaxial stress along the fibres (σ₂₂ = σ₃₃ = 0 fixes t) leaves
//     σ₁₁ = σ₁₁ − σ₂₂ = μ J^{−5/3} (λ² − t²) + (2/J) k₁ λ² (λ² − 1) exp(k₂ (λ² − 1)²),
// and in the incompressible limit (κ → ∞: J → 1, t = λ^{−1/2})
//     σ₁₁ = μ (λ² − 1/λ) + 2 k₁ λ² (λ² − 1) exp(k₂ (λ² − 1)²).
// Across the fibres (stretch λ along e₂) the lateral contraction shortens the fibre, which
// goes slack: the response is the matrix's, σ₂₂ = μ J^{−5/3} (λ² − t²).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "coapt/solid/materials.hpp"
#include "material_test_support.hpp"

namespace {

using namespace coapt::solid;
using coapt::solid::testing::bisect;
using coapt::solid::testing::finite_difference_gradient;
using coapt::solid::testing::finite_difference_tangent;
using coapt::solid::testing::random_deformation;
using coapt::solid::testing::relative_difference;

const FibreReinforced kLeaflet{.shear_modulus = 1.0e5,
                               .bulk_modulus = 5.0e6,
                               .fibre_k1 = 2.0e5,
                               .fibre_k2 = 5.0,
                               .n_fibre_families = 1};

FibreDirections fibre_along(const Vector3& direction) {
  FibreDirections fibres;
  fibres.a0[0] = direction.normalized();
  return fibres;
}

// σ for F = diag(λ, t, t), a₀ = e₁ (file comment).
Matrix3 closed_form_stress(const FibreReinforced& law, double lambda, double t) {
  const double J = lambda * t * t;
  const double mu_J = law.shear_modulus * std::pow(J, -5.0 / 3.0);
  const double difference = lambda * lambda - t * t;
  const double pressure_part = law.bulk_modulus * (J - 1.0 / J) / 2.0;
  const double e = lambda * lambda - 1.0;
  const double fibre =
      e > 0.0 ? 2.0 / J * law.fibre_k1 * e * std::exp(law.fibre_k2 * e * e) * lambda * lambda : 0.0;
  return Vector3(2.0 / 3.0 * mu_J * difference + pressure_part + fibre,
                 -1.0 / 3.0 * mu_J * difference + pressure_part,
                 -1.0 / 3.0 * mu_J * difference + pressure_part)
      .asDiagonal();
}

Matrix3 diagonal(double a, double b, double c) {
  return Vector3(a, b, c).asDiagonal();
}

TEST(FibreReinforced, StressOfAnAxialStretchMatchesClosedForm) {
  const FibreDirections fibres = fibre_along(Vector3::UnitX());
  const std::pair<double, double> stretches[] = {{1.2, 0.93}, {1.05, 1.0}, {0.9, 1.04}, {1.3, 1.1}};
  for (const auto& [lambda, t] : stretches) {
    const Matrix3 expected = closed_form_stress(kLeaflet, lambda, t);
    const Matrix3 sigma = cauchy(kLeaflet, diagonal(lambda, t, t), fibres);
    EXPECT_LE((sigma - expected).norm(), 1e-12 * expected.norm())
        << "lambda = " << lambda << ", t = " << t;
  }
}

// Lateral stretch t that makes σ₂₂ = σ₃₃ = 0 for an axial stretch λ along e₁.
double free_lateral_stretch(const FibreReinforced& law, const FibreDirections& fibres,
                            double lambda) {
  return bisect([&](double t) { return cauchy(law, diagonal(lambda, t, t), fibres)(1, 1); }, 0.5,
                1.5);
}

TEST(FibreReinforced, UniaxialStressAlongTheFibres) {
  const FibreDirections fibres = fibre_along(Vector3::UnitX());
  for (double lambda : {1.05, 1.15, 1.3}) {
    const double t = free_lateral_stretch(kLeaflet, fibres, lambda);
    const Matrix3 sigma = cauchy(kLeaflet, diagonal(lambda, t, t), fibres);
    const double J = lambda * t * t, e = lambda * lambda - 1.0;
    const double expected =
        kLeaflet.shear_modulus * std::pow(J, -5.0 / 3.0) * (lambda * lambda - t * t) +
        2.0 / J * kLeaflet.fibre_k1 * lambda * lambda * e * std::exp(kLeaflet.fibre_k2 * e * e);
    EXPECT_NEAR(sigma(0, 0), expected, 1e-9 * expected) << "lambda = " << lambda;
    EXPECT_NEAR(sigma(2, 2), 0.0, 1e-9 * expected);
    // The fibres carry most of it: stiffer than the matrix alone.
    EXPECT_GT(sigma(0, 0), 2.0 * cauchy(kLeaflet.matrix(), diagonal(lambda, t, t))(0, 0));
  }
}

TEST(FibreReinforced, UniaxialStressAlongTheFibresIncompressibleLimit) {
  FibreReinforced law = kLeaflet;
  law.bulk_modulus = 1.0e5 * law.shear_modulus;
  const FibreDirections fibres = fibre_along(Vector3::UnitX());
  for (double lambda : {1.05, 1.15, 1.3}) {
    const double t = free_lateral_stretch(law, fibres, lambda);
    EXPECT_NEAR(t, 1.0 / std::sqrt(lambda), 1e-4);
    const double e = lambda * lambda - 1.0;
    const double expected =
        law.shear_modulus * (lambda * lambda - 1.0 / lambda) +
        2.0 * law.fibre_k1 * lambda * lambda * e * std::exp(law.fibre_k2 * e * e);
    EXPECT_NEAR(cauchy(law, diagonal(lambda, t, t), fibres)(0, 0), expected, 1e-3 * expected);
  }
}

TEST(FibreReinforced, UniaxialStressAcrossTheFibresIsTheMatrixResponse) {
  const FibreDirections fibres = fibre_along(Vector3::UnitX());
  for (double lambda : {1.1, 1.3}) {
    // Stretch λ along e₂; the fibre direction e₁ and e₃ contract by the same t.
    const auto F_of = [&](double t) { return diagonal(t, lambda, t); };
    const double t =
        bisect([&](double s) { return cauchy(kLeaflet, F_of(s), fibres)(0, 0); }, 0.5, 1.5);
    ASSERT_LT(t, 1.0);  // the fibre is shortened, hence slack
    const Matrix3 sigma = cauchy(kLeaflet, F_of(t), fibres);
    const double J = lambda * t * t;
    const double expected =
        kLeaflet.shear_modulus * std::pow(J, -5.0 / 3.0) * (lambda * lambda - t * t);
    EXPECT_NEAR(sigma(1, 1), expected, 1e-9 * expected);
    EXPECT_NEAR(sigma(2, 2), 0.0, 1e-9 * expected);
    EXPECT_EQ(first_piola(kLeaflet, F_of(t), fibres), kLeaflet.matrix().first_piola(F_of(t)));
  }
}

// Tension only: with every fibre shortened, energy, stress and tangent are the matrix's.
TEST(FibreReinforced, NoFibreContributionInCompression) {
  FibreReinforced law = kLeaflet;
  law.n_fibre_families = 2;
  FibreDirections fibres;
  fibres.a0[0] = Vector3(1.0, 0.3, 0.0).normalized();
  fibres.a0[1] = Vector3(1.0, -0.3, 0.1).normalized();
  std::vector<Matrix3> deformations = {diagonal(0.85, 1.08, 1.08), diagonal(0.95, 1.2, 0.9)};
  std::mt19937 rng(51);
  while (deformations.size() < 8) {
    const Matrix3 F = random_deformation(rng, 0.3);
    if ((F * fibres.a0[0]).squaredNorm() < 1.0 && (F * fibres.a0[1]).squaredNorm() < 1.0)
      deformations.push_back(F);
  }
  const NearlyIncompressibleNeoHookean matrix = law.matrix();
  for (const Matrix3& F : deformations) {
    EXPECT_EQ(law.energy(F, fibres), matrix.energy(F));
    EXPECT_EQ(law.first_piola(F, fibres), matrix.first_piola(F));
    EXPECT_EQ(law.tangent(F, fibres), matrix.tangent(F));
  }
}

// Pure dilatation F = sI. With the full I₄ = s² the fibres resist a volume increase and the
// stress is not spherical:
//   σ = κ U'(J) I + (2/J) k₁ (s² − 1) exp(k₂ (s² − 1)²) s² a₀ ⊗ a₀,  J = s³,
// whose deviator is that of a uniaxial stress, so von Mises = the fibre coefficient. With the
// isochoric Ī₄ = J^{−2/3} I₄ = 1 the fibres would stay unloaded and σ would be spherical for
// every s. Under a volume decrease (s < 1) the fibres are slack and σ is spherical.
TEST(FibreReinforced, PureDilatationLoadsStretchedFibresOnly) {
  const Vector3 a0 = Vector3(1.0, 2.0, -0.5).normalized();
  const FibreDirections fibres = fibre_along(a0);
  for (double s : {1.03, 1.1}) {
    const double J = s * s * s, e = s * s - 1.0;
    const double fibre =
        2.0 / J * kLeaflet.fibre_k1 * e * std::exp(kLeaflet.fibre_k2 * e * e) * s * s;
    const Matrix3 expected = kLeaflet.bulk_modulus * (J - 1.0 / J) / 2.0 * Matrix3::Identity() +
                             fibre * a0 * a0.transpose();
    const Matrix3 sigma = cauchy(kLeaflet, s * Matrix3::Identity(), fibres);
    EXPECT_LE((sigma - expected).norm(), 1e-12 * expected.norm()) << "s = " << s;
    EXPECT_NEAR(von_mises(sigma), fibre, 1e-9 * fibre);
    EXPECT_GT(von_mises(sigma), 1e-2 * std::abs(sigma.trace()));  // far from spherical
  }
  for (double s : {0.9, 0.97}) {
    const double J = s * s * s;
    const Matrix3 sigma = cauchy(kLeaflet, s * Matrix3::Identity(), fibres);
    EXPECT_LE((sigma - kLeaflet.bulk_modulus * (J - 1.0 / J) / 2.0 * Matrix3::Identity()).norm(),
              1e-12 * sigma.norm());
    EXPECT_LE(von_mises(sigma), 1e-12 * sigma.norm());
  }
}

// The converse (Sansour 2008): a hydrostatic tension must not give a spherical deformation.
// For F = diag(λ₁, λ₂, λ₂), a₀ = e₁, σ₁₁ − σ₂₂ = μ J^{−5/3} (λ₁² − λ₂²) + fibre(λ₁) is
// positive at λ₁ = λ₂ > 1 and negative at λ₁ = 1, so the spherical state has 1 < λ₁ < λ₂:
// the fibre direction stretches less. (With Ī₄ the root would be λ₁ = λ₂.)
TEST(FibreReinforced, HydrostaticTensionGivesANonSphericalDeformation) {
  const FibreDirections fibres = fibre_along(Vector3::UnitX());
  const double lambda2 = 1.02;
  const auto F_of = [&](double lambda1) { return diagonal(lambda1, lambda2, lambda2); };
  const double lambda1 = bisect(
      [&](double l) {
        const Matrix3 sigma = cauchy(kLeaflet, F_of(l), fibres);
        return sigma(0, 0) - sigma(1, 1);
      },
      1.0, lambda2);
  const Matrix3 sigma = cauchy(kLeaflet, F_of(lambda1), fibres);
  EXPECT_GT(sigma.trace(), 0.0);                         // hydrostatic tension ...
  EXPECT_LE(von_mises(sigma), 1e-9 * sigma.norm());      // ... and nothing else
  EXPECT_LT(lambda1, lambda2 - 0.25 * (lambda2 - 1.0));  // clearly non-spherical
}

// Small strain with the fibre stretched: ψ' ≈ k₁ e, e ≈ 2 a₀·ε a₀, so
//   P(I + εH) = C:ε + 4 k₁ (a₀·ε a₀) a₀ ⊗ a₀ + O(ε²).
TEST(FibreReinforced, SmallStrainWithStretchedFibre) {
  const Vector3 a0 = Vector3(1.0, 2.0, -0.5).normalized();
  const FibreDirections fibres = fibre_along(a0);
  Matrix3 H;
  H << 0.4, 0.3, -0.2, 0.1, 0.5, 0.2, -0.3, 0.2, -0.1;
  ASSERT_GT(a0.dot(H * a0), 0.1);
  const Tangent3 C = isotropic_elasticity_tensor(
      kLeaflet.bulk_modulus - 2.0 / 3.0 * kLeaflet.shear_modulus, kLeaflet.shear_modulus);
  for (double epsilon : {1e-2, 1e-3, 1e-4}) {
    const Matrix3 strain = 0.5 * epsilon * (H + H.transpose());
    Matrix3 expected;
    Eigen::Map<Eigen::Matrix<double, 9, 1>>(expected.data()) =
        C * Eigen::Map<const Eigen::Matrix<double, 9, 1>>(strain.data());
    expected += 4.0 * kLeaflet.fibre_k1 * a0.dot(strain * a0) * a0 * a0.transpose();
    const Matrix3 P = first_piola(kLeaflet, Matrix3::Identity() + epsilon * H, fibres);
    EXPECT_LE((P - expected).norm(), 10.0 * epsilon * epsilon * C.norm() * H.squaredNorm())
        << "epsilon = " << epsilon;
  }
}

// Derivatives at chosen states: both families stretched, and one stretched one slack.
TEST(FibreReinforced, DerivativesWithBothAndOneFamilyActive) {
  FibreReinforced law = kLeaflet;
  law.n_fibre_families = 2;
  const double angle = 40.0 * std::numbers::pi / 180.0;
  FibreDirections fibres;
  fibres.a0[0] = Vector3(std::cos(angle), std::sin(angle), 0.0);
  fibres.a0[1] = Vector3(std::cos(angle), -std::sin(angle), 0.0);
  Matrix3 both = diagonal(1.2, 1.1, 0.75);
  Matrix3 one = diagonal(1.1, 0.8, 1.1);
  one(0, 1) = 0.3;
  for (const auto& [F, active] : {std::pair{both, 2}, std::pair{one, 1}}) {
    int n_active = 0;
    for (const Vector3& a0 : fibres.a0) n_active += (F * a0).squaredNorm() > 1.0 + 1e-2;
    ASSERT_EQ(n_active, active);
    const Matrix3 P_fd =
        finite_difference_gradient<3>([&](const Matrix3& G) { return law.energy(G, fibres); }, F);
    EXPECT_LT(relative_difference(law.first_piola(F, fibres), P_fd), 1e-6);
    const Tangent3 A_fd = finite_difference_tangent<3>(
        [&](const Matrix3& G) { return law.first_piola(G, fibres); }, F);
    EXPECT_LT(relative_difference(law.tangent(F, fibres), A_fd), 1e-6);
  }
}

// k₂ = 0 is the quadratic limit ψ_f = k₁/2 (I₄ − 1)².
TEST(FibreReinforced, ZeroK2IsTheQuadraticLimit) {
  FibreReinforced law = kLeaflet;
  law.fibre_k2 = 0.0;
  const FibreDirections fibres = fibre_along(Vector3::UnitX());
  const Matrix3 F = diagonal(1.2, 0.95, 0.9);
  const double e = 1.2 * 1.2 - 1.0;
  EXPECT_NEAR(law.energy(F, fibres) - law.matrix().energy(F), 0.5 * law.fibre_k1 * e * e,
              1e-10 * law.fibre_k1);
}

}  // namespace
