// Properties every constitutive law must have (stress-free reference, P = ∂ψ/∂F,
// A = ∂P/∂F, major symmetry, objectivity, small-strain limit, plane-strain wrapper), the
// law-specific checks of the isotropic laws, von Mises, and the parameter validation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/solid/materials.hpp"
#include "material_test_support.hpp"

namespace {

using namespace coapt::solid;
using coapt::solid::testing::finite_difference_gradient;
using coapt::solid::testing::finite_difference_tangent;
using coapt::solid::testing::random_deformation;
using coapt::solid::testing::random_rotation;
using coapt::solid::testing::relative_difference;

// --- The laws under test -----------------------------------------------------------------

struct LawCase {
  std::string label;
  Material material;
  FibreDirections fibres;
};

std::ostream& operator<<(std::ostream& out, const LawCase& law_case) {
  return out << law_case.label;
}

std::string case_name(const ::testing::TestParamInfo<LawCase>& info) {
  return info.param.label;
}

// Leaflet-like fibre parameters (Pa and -): the fibres are stiffer than the matrix.
FibreReinforced fibre_law(int n_families, double k2 = 5.0) {
  return {.shear_modulus = 1.0e5,
          .bulk_modulus = 5.0e6,
          .fibre_k1 = 2.0e5,
          .fibre_k2 = k2,
          .n_fibre_families = n_families};
}

// One oblique family; two families at ±40° from x (tilted out of the x–y plane unless
// in_plane); one in-plane family for plane strain.
FibreDirections oblique_fibres() {
  FibreDirections fibres;
  fibres.a0[0] = Vector3(1.0, 2.0, 0.5).normalized();
  return fibres;
}
FibreDirections crossed_fibres(bool in_plane) {
  const double angle = 40.0 * std::numbers::pi / 180.0;
  const double tilt = in_plane ? 0.0 : 0.3;
  FibreDirections fibres;
  fibres.a0[0] = Vector3(std::cos(angle), std::sin(angle), tilt).normalized();
  fibres.a0[1] = Vector3(std::cos(angle), -std::sin(angle), tilt).normalized();
  return fibres;
}
FibreDirections in_plane_fibre() {
  FibreDirections fibres;
  fibres.a0[0] = Vector3(std::cos(0.5), std::sin(0.5), 0.0);
  return fibres;
}

std::vector<LawCase> finite_strain_cases() {
  return {
      {"saint_venant_kirchhoff", SaintVenantKirchhoff::from_young_poisson(2.0e6, 0.3), {}},
      {"neo_hookean", NeoHookean::from_young_poisson(2.0e6, 0.45), {}},
      {"nearly_incompressible_neo_hookean", NearlyIncompressibleNeoHookean{1.0e5, 5.0e6}, {}},
      {"fibre_one_family", fibre_law(1), oblique_fibres()},
      {"fibre_two_families", fibre_law(2), crossed_fibres(false)},
      {"fibre_two_families_k2_zero", fibre_law(2, 0.0), crossed_fibres(false)},
  };
}

std::vector<LawCase> all_cases() {
  std::vector<LawCase> cases = {
      {"linear_elastic", LinearElastic::from_young_poisson(2.0e6, 0.3), {}}};
  for (const LawCase& law_case : finite_strain_cases()) cases.push_back(law_case);
  return cases;
}

std::vector<LawCase> plane_strain_cases() {
  return {
      {"linear_elastic", LinearElastic::from_young_poisson(2.0e6, 0.3), {}},
      {"saint_venant_kirchhoff", SaintVenantKirchhoff::from_young_poisson(2.0e6, 0.3), {}},
      {"neo_hookean", NeoHookean::from_young_poisson(2.0e6, 0.45), {}},
      {"nearly_incompressible_neo_hookean", NearlyIncompressibleNeoHookean{1.0e5, 5.0e6}, {}},
      {"fibre_one_family", fibre_law(1), in_plane_fibre()},
      {"fibre_two_families", fibre_law(2), crossed_fibres(true)},
  };
}

// The small-strain elasticity tensor every law reduces to at F = I (fibres slack).
Tangent3 small_strain_tensor(const Material& material) {
  return std::visit(
      [](const auto& law) -> Tangent3 {
        if constexpr (requires { law.lambda; })
          return isotropic_elasticity_tensor(law.lambda, law.shear_modulus);
        else
          return isotropic_elasticity_tensor(law.bulk_modulus - 2.0 / 3.0 * law.shear_modulus,
                                             law.shear_modulus);
      },
      material);
}

int n_fibre_families(const Material& material) {
  const auto* fibre = std::get_if<FibreReinforced>(&material);
  return fibre ? fibre->n_fibre_families : 0;
}

// I₄ − 1 of each fibre family.
std::vector<double> fibre_strains(const LawCase& law_case, const Matrix3& F) {
  std::vector<double> strains;
  for (int f = 0; f < n_fibre_families(law_case.material); ++f) {
    const Vector3 a = F * law_case.fibres.a0[f];
    strains.push_back(a.squaredNorm() - 1.0);
  }
  return strains;
}

// A random 2×2 deformation gradient with det F > 0.5.
Matrix2 random_deformation_2d(std::mt19937& rng) {
  for (;;) {
    const Matrix2 F = random_deformation(rng).topLeftCorner<2, 2>();
    if (F.determinant() > 0.5) return F;
  }
}

// Random deformations away from the fibres' kink at I₄ = 1 (where A jumps), so that
// central differences see a smooth function.
std::vector<Matrix3> smooth_samples(const LawCase& law_case, int count, std::mt19937& rng) {
  std::vector<Matrix3> samples;
  while (static_cast<int>(samples.size()) < count) {
    const Matrix3 F = random_deformation(rng);
    bool near_kink = false;
    for (double e : fibre_strains(law_case, F)) near_kink = near_kink || std::abs(e) < 1e-3;
    if (!near_kink) samples.push_back(F);
  }
  return samples;
}

// The 9×9 matrix Q̂ with Q̂(3i+J, 3a+K) = Q_ia δ_JK: flattened, (QX) = Q̂ vec(X).
Tangent3 rotate_spatial_index(const Matrix3& Q) {
  Tangent3 rotation = Tangent3::Zero();
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a)
      for (int J = 0; J < 3; ++J) rotation(3 * i + J, 3 * a + J) = Q(i, a);
  return rotation;
}

// --- Properties of every law ---------------------------------------------------------------

class MaterialLaw : public ::testing::TestWithParam<LawCase> {};

TEST_P(MaterialLaw, ReferenceStateIsStressFree) {
  const LawCase& law = GetParam();
  const Matrix3 I = Matrix3::Identity();
  EXPECT_EQ(energy(law.material, I, law.fibres), 0.0);
  EXPECT_LE(first_piola(law.material, I, law.fibres).norm(), 1e-20);
  EXPECT_LE(cauchy(law.material, I, law.fibres).norm(), 1e-20);
}

TEST_P(MaterialLaw, StressIsGradientOfEnergy) {
  const LawCase& law = GetParam();
  std::mt19937 rng(11);
  int active_fibres = 0;
  for (const Matrix3& F : smooth_samples(law, 8, rng)) {
    const Matrix3 P = first_piola(law.material, F, law.fibres);
    const Matrix3 P_fd = finite_difference_gradient<3>(
        [&](const Matrix3& G) { return energy(law.material, G, law.fibres); }, F);
    EXPECT_LT(relative_difference(P, P_fd), 1e-6) << "F =\n" << F;
    for (double e : fibre_strains(law, F)) active_fibres += e > 0.0;
  }
  if (n_fibre_families(law.material) > 0) {
    EXPECT_GT(active_fibres, 2) << "fibres rarely loaded";
  }
}

TEST_P(MaterialLaw, TangentIsGradientOfStress) {
  const LawCase& law = GetParam();
  std::mt19937 rng(12);
  for (const Matrix3& F : smooth_samples(law, 8, rng)) {
    const Tangent3 A = tangent(law.material, F, law.fibres);
    const Tangent3 A_fd = finite_difference_tangent<3>(
        [&](const Matrix3& G) { return first_piola(law.material, G, law.fibres); }, F);
    EXPECT_LT(relative_difference(A, A_fd), 1e-6) << "F =\n" << F;
  }
}

TEST_P(MaterialLaw, TangentHasMajorSymmetry) {
  const LawCase& law = GetParam();
  std::mt19937 rng(13);
  for (const Matrix3& F : smooth_samples(law, 8, rng)) {
    const Tangent3 A = tangent(law.material, F, law.fibres);
    EXPECT_LE((A - A.transpose()).norm(), 1e-13 * A.norm()) << "F =\n" << F;
  }
}

// ‖P(I + εH) − C:sym(εH)‖ = O(ε²) with C the small-strain tensor; for fibre laws H
// shortens every fibre (a stretched fibre adds 4k₁ (a₀·εa₀) a₀⊗a₀: see the fibre tests).
TEST_P(MaterialLaw, SmallStrainLimitIsLinearElasticity) {
  const LawCase& law = GetParam();
  const Tangent3 C = small_strain_tensor(law.material);
  const Matrix3 I = Matrix3::Identity();
  EXPECT_LE((tangent(law.material, I, law.fibres) - C).norm(), 1e-12 * C.norm());

  std::mt19937 rng(14);
  Matrix3 H;
  for (;;) {
    H = random_deformation(rng, 1.0) - I;
    bool all_shortened = true;
    for (double e : fibre_strains(law, I + 1e-6 * H)) all_shortened = all_shortened && e < 0.0;
    if (all_shortened) break;
  }
  for (double epsilon : {1e-2, 1e-3, 1e-4}) {
    const Matrix3 strain = 0.5 * epsilon * (H + H.transpose());
    Matrix3 linear_stress;
    Eigen::Map<Eigen::Matrix<double, 9, 1>>(linear_stress.data()) =
        C * Eigen::Map<const Eigen::Matrix<double, 9, 1>>(strain.data());
    // (the flattening order does not matter here: C has minor and major symmetry)
    const Matrix3 P = first_piola(law.material, I + epsilon * H, law.fibres);
    EXPECT_LE((P - linear_stress).norm(), 10.0 * epsilon * epsilon * C.norm() * H.squaredNorm())
        << "epsilon = " << epsilon;
  }
}

// Near F = I the energy is O(|H|²) while F is O(1): ψ(I + εH) must still match
// ε²/2 sym H : C : sym H to O(ε) — a naive ln(det F) or J^{-2/3} I₁ − 3 loses all digits.
TEST_P(MaterialLaw, EnergyKeepsItsDigitsNearTheReference) {
  const LawCase& law = GetParam();
  const Tangent3 C = small_strain_tensor(law.material);
  const Matrix3 I = Matrix3::Identity();
  Matrix3 H;
  H << -0.3, -0.2, 0.1, 0.4, -0.5, 0.2, -0.1, 0.3, -0.4;  // sym H < 0: shortens every fibre
  for (double epsilon : {1e-5, 1e-7, 1e-9}) {
    const Matrix3 F = I + epsilon * H;
    for (double e : fibre_strains(law, F)) ASSERT_LT(e, 0.0);
    const Matrix3 H_stored = F - I;  // what F holds of εH (exact: Sterbenz)
    const Matrix3 strain = 0.5 * (H_stored + H_stored.transpose());
    const Eigen::Map<const Eigen::Matrix<double, 9, 1>> flat(strain.data());
    const double quadratic = 0.5 * flat.dot(C * flat);
    EXPECT_NEAR(energy(law.material, F, law.fibres), quadratic,
                (100.0 * epsilon + 1e-12) * quadratic)
        << "epsilon = " << epsilon;
  }
}

INSTANTIATE_TEST_SUITE_P(Solid, MaterialLaw, ::testing::ValuesIn(all_cases()), case_name);

// --- Properties of the finite-strain laws ----------------------------------------------------

class FiniteStrainLaw : public ::testing::TestWithParam<LawCase> {};

TEST_P(FiniteStrainLaw, IsObjective) {
  const LawCase& law = GetParam();
  std::mt19937 rng(15);
  for (const Matrix3& F : smooth_samples(law, 8, rng)) {
    const Matrix3 Q = random_rotation(rng);
    const Matrix3 P = first_piola(law.material, F, law.fibres);
    EXPECT_NEAR(energy(law.material, Q * F, law.fibres), energy(law.material, F, law.fibres),
                1e-12 * std::abs(energy(law.material, F, law.fibres)));
    EXPECT_LE((first_piola(law.material, Q * F, law.fibres) - Q * P).norm(), 1e-12 * P.norm());
    // A(QF)_iJkL = Q_ia Q_kb A(F)_aJbL
    const Tangent3 A = tangent(law.material, F, law.fibres);
    const Tangent3 Q_hat = rotate_spatial_index(Q);
    EXPECT_LE((tangent(law.material, Q * F, law.fibres) - Q_hat * A * Q_hat.transpose()).norm(),
              1e-12 * A.norm());
  }
}

TEST_P(FiniteStrainLaw, CauchyStressIsSymmetric) {
  const LawCase& law = GetParam();
  std::mt19937 rng(16);
  for (const Matrix3& F : smooth_samples(law, 8, rng)) {
    const Matrix3 sigma = cauchy(law.material, F, law.fibres);
    EXPECT_LE((sigma - sigma.transpose()).norm(), 1e-12 * sigma.norm());
  }
}

INSTANTIATE_TEST_SUITE_P(Solid, FiniteStrainLaw, ::testing::ValuesIn(finite_strain_cases()),
                         case_name);

// --- Plane strain ------------------------------------------------------------------------------

class PlaneStrainLaw : public ::testing::TestWithParam<LawCase> {};

TEST_P(PlaneStrainLaw, IsTheInPlanePartOfThe3DLaw) {
  const LawCase& law = GetParam();
  std::mt19937 rng(17);
  for (int sample = 0; sample < 8; ++sample) {
    const Matrix2 F = random_deformation_2d(rng);
    Matrix3 F3 = Matrix3::Identity();
    F3.topLeftCorner<2, 2>() = F;
    ASSERT_EQ(plane_strain::embed(F), F3);

    EXPECT_EQ(plane_strain::energy(law.material, F, law.fibres),
              energy(law.material, F3, law.fibres));
    const Matrix3 P3 = first_piola(law.material, F3, law.fibres);
    const Matrix2 P = plane_strain::first_piola(law.material, F, law.fibres);
    const Tangent3 A3 = tangent(law.material, F3, law.fibres);
    const Tangent2 A = plane_strain::tangent(law.material, F, law.fibres);
    for (int i = 0; i < 2; ++i)
      for (int J = 0; J < 2; ++J) {
        EXPECT_EQ(P(i, J), P3(i, J));
        for (int k = 0; k < 2; ++k)
          for (int L = 0; L < 2; ++L) EXPECT_EQ(A(2 * i + J, 2 * k + L), A3(3 * i + J, 3 * k + L));
      }
    // No out-of-plane shear for in-plane deformations and fibres.
    for (int i = 0; i < 2; ++i) {
      EXPECT_LE(std::abs(P3(i, 2)), 1e-12 * P3.norm());
      EXPECT_LE(std::abs(P3(2, i)), 1e-12 * P3.norm());
    }
    EXPECT_EQ(plane_strain::cauchy(law.material, F, law.fibres),
              cauchy(law.material, F3, law.fibres));
  }
}

TEST_P(PlaneStrainLaw, StressAndTangentAreDerivativesIn2D) {
  const LawCase& law = GetParam();
  std::mt19937 rng(18);
  for (int sample = 0; sample < 8; ++sample) {
    const Matrix2 F = random_deformation_2d(rng);
    const Matrix2 P_fd = finite_difference_gradient<2>(
        [&](const Matrix2& G) { return plane_strain::energy(law.material, G, law.fibres); }, F);
    EXPECT_LT(relative_difference(plane_strain::first_piola(law.material, F, law.fibres), P_fd),
              1e-6);
    const Tangent2 A_fd = finite_difference_tangent<2>(
        [&](const Matrix2& G) { return plane_strain::first_piola(law.material, G, law.fibres); },
        F);
    EXPECT_LT(relative_difference(plane_strain::tangent(law.material, F, law.fibres), A_fd), 1e-6);
  }
}

INSTANTIATE_TEST_SUITE_P(Solid, PlaneStrainLaw, ::testing::ValuesIn(plane_strain_cases()),
                         case_name);

// Plane strain ε₁₁ = e: σ = ((λ+2μ)e, λe, λe), von Mises |σ₁₁ − σ₂₂| = 2μ|e|; it needs σ₃₃.
TEST(PlaneStrain, VonMisesIncludesTheOutOfPlaneStress) {
  const LinearElastic law = LinearElastic::from_young_poisson(2.0e6, 0.3);
  const double e = 1e-3;
  const Matrix3 sigma =
      plane_strain::cauchy(law, Matrix2(Eigen::Vector2d(1.0 + e, 1.0).asDiagonal()));
  EXPECT_NEAR(sigma(2, 2), law.lambda * e, 1e-9 * law.lambda * e);
  EXPECT_NEAR(von_mises(sigma), 2.0 * law.shear_modulus * e, 1e-9 * law.shear_modulus * e);
}

// --- Linear elasticity -------------------------------------------------------------------------

TEST(LinearElastic, IsInvariantUnderInfinitesimalRotations) {
  const LinearElastic law = LinearElastic::from_young_poisson(2.0e6, 0.3);
  std::mt19937 rng(21);
  const Matrix3 F = random_deformation(rng);
  Matrix3 W;
  W << 0.0, 0.3, -0.2, -0.3, 0.0, 0.1, 0.2, -0.1, 0.0;  // skew
  const Matrix3 P = law.first_piola(F);
  EXPECT_LE((law.first_piola(F + W) - P).norm(), 1e-15 * law.shear_modulus);
  EXPECT_NEAR(law.energy(F + W), law.energy(F), 1e-15 * law.energy(F));
}

// The documented limitation: a finite rotation by θ about z gives
// ε = −(1 − cos θ) (e₁⊗e₁ + e₂⊗e₂), a spurious stress of order μθ².
TEST(LinearElastic, FiniteRotationGivesSpuriousStressOfOrderThetaSquared) {
  const LinearElastic law = LinearElastic::from_young_poisson(2.0e6, 0.3);
  const double theta = 0.1;
  const Matrix3 Q = Eigen::AngleAxisd(theta, Vector3::UnitZ()).toRotationMatrix();
  const double e = -(1.0 - std::cos(theta));
  const Matrix3 expected =
      Vector3(2.0 * law.shear_modulus * e + 2.0 * law.lambda * e,
              2.0 * law.shear_modulus * e + 2.0 * law.lambda * e, 2.0 * law.lambda * e)
          .asDiagonal();
  EXPECT_LE((law.first_piola(Q) - expected).norm(), 1e-12 * expected.norm());
}

// --- Nearly incompressible Neo-Hookean -----------------------------------------------------

TEST(NearlyIncompressibleNeoHookean, PureDilatationGivesPressureFromU) {
  const NearlyIncompressibleNeoHookean law{1.0e5, 5.0e6};
  for (double s : {0.8, 0.95, 1.05, 1.3}) {
    const Matrix3 F = s * Matrix3::Identity();
    const double J = s * s * s;
    // U(J) = (J² − 1)/4 − ln(J)/2, U'(J) = (J − 1/J)/2: σ = κ U'(J) I, no isochoric part.
    const double U = (J * J - 1.0) / 4.0 - std::log(J) / 2.0;
    const double dU = (J - 1.0 / J) / 2.0;
    EXPECT_NEAR(law.energy(F), law.bulk_modulus * U, 1e-12 * law.bulk_modulus * U);
    const Matrix3 sigma = cauchy(law, F);
    EXPECT_LE((sigma - law.bulk_modulus * dU * Matrix3::Identity()).norm(),
              1e-12 * law.bulk_modulus * std::abs(dU))
        << "s = " << s;
    EXPECT_DOUBLE_EQ(NearlyIncompressibleNeoHookean::volumetric_energy_derivative(J), dU);
  }
}

TEST(NearlyIncompressibleNeoHookean, IsochoricDeformationGivesNoPressure) {
  const NearlyIncompressibleNeoHookean law{1.0e5, 5.0e6};
  std::mt19937 rng(31);
  std::vector<Matrix3> deformations;
  const double stretch = 1.4;
  deformations.push_back(
      Vector3(stretch, 1.0 / std::sqrt(stretch), 1.0 / std::sqrt(stretch)).asDiagonal());
  Matrix3 shear = Matrix3::Identity();
  shear(0, 1) = 0.7;
  deformations.push_back(shear);
  for (int sample = 0; sample < 5; ++sample) {
    const Matrix3 F = random_deformation(rng, 0.4);
    deformations.push_back(F / std::cbrt(F.determinant()));
  }
  for (const Matrix3& F : deformations) {
    const Matrix3 sigma = cauchy(law, F);
    EXPECT_GT(von_mises(sigma), 1e-2 * law.shear_modulus);                     // it is loaded ...
    EXPECT_LE(std::abs(sigma.trace()), 1e-11 * sigma.norm()) << "F =\n" << F;  // ... without p
  }
}

// --- Cancellation-free scalar helpers ---------------------------------------------------------

// References in long double: the series with many terms where the direct form would cancel,
// the direct form elsewhere. The switch of the double versions at |x| = 0.01 is inside.
TEST(MaterialNumerics, SeriesMatchReferences) {
  for (double x : {-0.3, -0.0101, -0.0099, -1e-3, -1e-8, 1e-12, 1e-6, 0.0099, 0.0101, 0.5, 2.0}) {
    const long double xl = x;
    long double log_reference = xl - std::log1p(xl);
    long double exp_reference = std::expm1(xl) - xl;
    if (std::abs(x) < 0.4) {
      log_reference = exp_reference = 0.0L;
      long double power = xl * xl, factorial = 2.0L;
      for (int n = 2; n < 60; ++n) {
        log_reference += (n % 2 == 0 ? power : -power) / n;
        exp_reference += power / factorial;
        power *= xl;
        factorial *= n + 1;
      }
    }
    EXPECT_NEAR(x_minus_log1p(x), static_cast<double>(log_reference),
                1e-13 * static_cast<double>(std::abs(log_reference)))
        << "x = " << x;
    EXPECT_NEAR(expm1_minus_x(x), static_cast<double>(exp_reference),
                1e-13 * static_cast<double>(std::abs(exp_reference)))
        << "x = " << x;
  }
  EXPECT_EQ(expm1_over_x(0.0), 1.0);
  EXPECT_NEAR(expm1_over_x(1e-10), 1.0 + 5e-11, 1e-16);
}

TEST(MaterialNumerics, VolumeRatioKeepsTheDigitsOfJMinusOne) {
  Matrix3 H;
  H << 0.3, -0.2, 0.1, 0.4, -0.5, 0.2, -0.1, 0.3, -0.4;
  for (double epsilon : {1e-3, 1e-8, 1e-12}) {
    const Matrix3 F = Matrix3::Identity() + epsilon * H;
    const Matrix3 G = F - Matrix3::Identity();  // what F holds of εH
    // det(I + G) − 1 = I₁ + I₂ + I₃, each term exact enough in long double.
    const long double I1 = G.trace();
    const long double I2 = 0.5L * (I1 * I1 - static_cast<long double>((G * G).trace()));
    const long double I3 = G.determinant();
    const double reference = static_cast<double>(I1 + I2 + I3);
    const VolumeRatio volume = volume_ratio(F);
    EXPECT_NEAR(volume.J_minus_one, reference, 1e-14 * std::abs(reference));
    EXPECT_NEAR(volume.log_J, std::log1p(reference), 1e-14 * std::abs(reference));
  }
}

// --- Von Mises -----------------------------------------------------------------------------------

TEST(VonMises, UniaxialStressGivesItsMagnitude) {
  for (double s : {3.0e5, -2.0e5}) {
    const Matrix3 sigma = Vector3(s, 0.0, 0.0).asDiagonal();
    EXPECT_NEAR(von_mises(sigma), std::abs(s), 1e-12 * std::abs(s));
  }
}

TEST(VonMises, PureShearGivesSqrtThreeTau) {
  const double tau = 1.5e5;
  Matrix3 sigma = Matrix3::Zero();
  sigma(0, 2) = sigma(2, 0) = tau;
  EXPECT_NEAR(von_mises(sigma), std::sqrt(3.0) * tau, 1e-12 * tau);
  // Also as principal stresses (τ, −τ, 0), rotated anywhere.
  std::mt19937 rng(41);
  const Matrix3 Q = random_rotation(rng);
  const Matrix3 principal = Vector3(tau, -tau, 0.0).asDiagonal();
  EXPECT_NEAR(von_mises(Q * principal * Q.transpose()), std::sqrt(3.0) * tau, 1e-12 * tau);
}

TEST(VonMises, HydrostaticStressGivesZero) {
  EXPECT_LE(von_mises(-4.0e4 * Matrix3::Identity()), 1e-10);
}

// --- Parameters
// ------------------------------------------------------------------------------------

// Runs `action`, expects an InputError whose message contains `fragment`.
template <class Action>
void expect_input_error(Action action, const std::string& fragment) {
  try {
    action();
    ADD_FAILURE() << "no InputError; expected one mentioning '" << fragment << "'";
  } catch (const coapt::InputError& error) {
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
  }
}

TEST(MaterialParameters, ConvertsYoungAndPoisson) {
  const double E = 2.0e6, nu = 0.3;
  const LameParameters lame = lame_from_young_poisson(E, nu);
  EXPECT_NEAR(lame.mu, E / 2.6, 1e-9);
  EXPECT_NEAR(lame.lambda, E * 0.3 / (1.3 * 0.4), 1e-9);
  EXPECT_NEAR(bulk_from_young_poisson(E, nu), lame.lambda + 2.0 / 3.0 * lame.mu, 1e-9);
  const auto law = NearlyIncompressibleNeoHookean::from_young_poisson(E, nu);
  EXPECT_EQ(law.shear_modulus, lame.mu);
  EXPECT_EQ(law.bulk_modulus, bulk_from_young_poisson(E, nu));
}

TEST(MaterialParameters, RejectsBadYoungOrPoisson) {
  expect_input_error([] { lame_from_young_poisson(2.0e6, 0.5, "stent"); }, "stent.poisson_ratio");
  expect_input_error([] { lame_from_young_poisson(2.0e6, -1.0, "stent"); }, "stent.poisson_ratio");
  expect_input_error([] { bulk_from_young_poisson(0.0, 0.3, "root"); }, "root.young_modulus");
  expect_input_error([] { LinearElastic::from_young_poisson(-1.0, 0.3); },
                     "linear_elastic.young_modulus");
  expect_input_error([] { NeoHookean::from_young_poisson(1.0, NAN); }, "finite");
}

TEST(MaterialParameters, ValidateNamesTheBadParameter) {
  EXPECT_NO_THROW(LinearElastic::from_young_poisson(2.0e6, 0.3).validate());
  expect_input_error([] { LinearElastic{1.0e6, -1.0}.validate("stent"); }, "stent.shear_modulus");
  expect_input_error(
      [] {
        SaintVenantKirchhoff{-1.0e6, 1.0e6}.validate();
      },
      "saint_venant_kirchhoff.lambda");  // bulk modulus λ + 2μ/3 < 0
  expect_input_error([] { NeoHookean{INFINITY, 1.0e6}.validate(); }, "finite");
  expect_input_error(
      [] {
        NearlyIncompressibleNeoHookean{1.0e5, 0.0}.validate("root");
      },
      "root.bulk_modulus");
  expect_input_error(
      [] {
        NearlyIncompressibleNeoHookean{-1.0e5, 1.0e6}.validate();
      },
      "shear_modulus");

  EXPECT_NO_THROW(fibre_law(2).validate());
  FibreReinforced bad = fibre_law(1);
  bad.fibre_k1 = -1.0;
  expect_input_error([&] { bad.validate("leaflet"); }, "leaflet.fibre_k1");
  bad = fibre_law(1);
  bad.fibre_k2 = -0.1;
  expect_input_error([&] { bad.validate("leaflet"); }, "leaflet.fibre_k2");
  bad = fibre_law(3);
  expect_input_error([&] { bad.validate("leaflet"); }, "leaflet.n_fibre_families");
  bad = fibre_law(1);
  bad.bulk_modulus = -5.0;
  expect_input_error([&] { validate(Material{bad}, "leaflet"); }, "leaflet.bulk_modulus");
}

TEST(MaterialParameters, FibreDirectionsMustBeUnitVectors) {
  const Material one_family = fibre_law(1);
  FibreDirections fibres = oblique_fibres();
  EXPECT_NO_THROW(validate_fibres(one_family, fibres, "element 7"));  // second one unused
  fibres.a0[0] *= 1.01;
  expect_input_error([&] { validate_fibres(one_family, fibres, "element 7"); }, "element 7");
  expect_input_error([&] { validate_fibres(fibre_law(2), oblique_fibres()); }, "direction 1");
  EXPECT_NO_THROW(validate_fibres(NeoHookean{1.0, 1.0}, FibreDirections{}));
}

TEST(MaterialParameters, NamesTheLaw) {
  EXPECT_EQ(name(LinearElastic{1.0, 1.0}), "linear_elastic");
  EXPECT_EQ(name(SaintVenantKirchhoff{1.0, 1.0}), "saint_venant_kirchhoff");
  EXPECT_EQ(name(NeoHookean{1.0, 1.0}), "neo_hookean");
  EXPECT_EQ(name(NearlyIncompressibleNeoHookean{1.0, 1.0}), "nearly_incompressible_neo_hookean");
  EXPECT_EQ(name(fibre_law(1)), "fibre_reinforced");
}

}  // namespace
