#pragma once
/// @file material_common.hpp
/// What the constitutive laws share: tensor types and the index convention of the tangent,
/// kinematic quantities computed without cancellation near the reference state, the
/// building blocks of the tangents, and the von Mises stress.
///
/// Conventions (total Lagrangian, 3D; the 2D plane-strain wrapper is in materials.hpp):
///  - F = I + ∇u the deformation gradient (3×3, det F > 0), H = F − I,
///    C = FᵀF, E = (C − I)/2 = (H + Hᵀ + HᵀH)/2, J = det F.
///  - P = ∂ψ/∂F the first Piola–Kirchhoff stress [Pa] (3×3, P_iJ: i spatial, J material).
///  - The consistent tangent A = ∂P/∂F is a 9×9 matrix with
///        A(3i + J, 3k + L) = ∂P_iJ / ∂F_kL,
///    i.e. P and F flattened row by row. A hyperelastic law has A_iJkL = A_kLiJ (A = Aᵀ).

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>

namespace coapt::solid {

using Matrix3 = Eigen::Matrix3d;
using Matrix2 = Eigen::Matrix2d;
using Vector3 = Eigen::Vector3d;
/// ∂P/∂F in 3D: A(3i + J, 3k + L) = ∂P_iJ/∂F_kL [Pa].
using Tangent3 = Eigen::Matrix<double, 9, 9>;
/// ∂P/∂F in 2D (plane strain): A(2i + J, 2k + L) = ∂P_iJ/∂F_kL [Pa].
using Tangent2 = Eigen::Matrix4d;

/// Row of the 9×9 tangent (or entry of row-flattened P) holding the component (i, J).
constexpr int tangent_index(int i, int J) {
  return 3 * i + J;
}

// --- Scalar functions evaluated without cancellation -----------------------------------

/// x − log(1 + x) for x > −1. Near 0 the difference is ≈ x²/2 and subtracting would lose
/// about log10(1/|x|) digits, so there it is summed as the series Σ_{n≥2} (−x)ⁿ/n (nine terms
/// reach round-off for |x| < 0.01; above it the direct form loses less than 2 digits).
inline double x_minus_log1p(double x) {
  if (std::abs(x) < 0.01) {
    double sum = 0.0;
    double power = x * x;  // xⁿ
    for (int n = 2; n <= 10; ++n) {
      sum += (n % 2 == 0 ? power : -power) / n;
      power *= x;
    }
    return sum;
  }
  return x - std::log1p(x);
}

/// eˣ − 1 − x, summed as Σ_{n≥2} xⁿ/n! near 0 for the same reason as x_minus_log1p.
inline double expm1_minus_x(double x) {
  if (std::abs(x) < 0.01) {
    double sum = 0.0;
    double term = 0.5 * x * x;  // xⁿ/n!
    for (int n = 2; n <= 8; ++n) {
      sum += term;
      term *= x / (n + 1);
    }
    return sum;
  }
  return std::expm1(x) - x;
}

/// (eˣ − 1)/x, continued by its limit 1 at x = 0.
inline double expm1_over_x(double x) {
  return x == 0.0 ? 1.0 : std::expm1(x) / x;
}

// --- Kinematics --------------------------------------------------------------------------

/// J = det F with J − 1 and ln J computed from H = F − I without cancellation:
/// det(I + H) − 1 = I₁(H) + I₂(H) + I₃(H) exactly, and ln J = log1p(J − 1) (as libCEED's
/// hyperelastic kernels do). Forming H from F is exact for diagonal entries in [0.5, 2]
/// (Sterbenz), so this keeps every digit F carries; det F − 1 would keep only |J − 1|/ε.
struct VolumeRatio {
  double J = 1.0;            ///< det F [-]
  double J_minus_one = 0.0;  ///< J − 1 [-]
  double log_J = 0.0;        ///< ln J [-]; NaN for J < 0, −∞ for J = 0
};

/// I₂(H) + I₃(H) = ((tr H)² − tr H²)/2 + det H: the part of det(I + H) − 1 beyond tr H.
inline double second_plus_third_invariant(const Matrix3& H) {
  const double trace = H.trace();
  return 0.5 * (trace * trace - (H * H).trace()) + H.determinant();
}

/// The volume ratio of F, see VolumeRatio.
inline VolumeRatio volume_ratio(const Matrix3& F) {
  const Matrix3 H = F - Matrix3::Identity();
  const double J_minus_one = H.trace() + second_plus_third_invariant(H);
  return {1.0 + J_minus_one, J_minus_one, std::log1p(J_minus_one)};
}

/// Green–Lagrange strain E = (FᵀF − I)/2, formed as (H + Hᵀ + HᵀH)/2 so that small strains
/// keep their digits.
inline Matrix3 green_lagrange_strain(const Matrix3& F) {
  const Matrix3 H = F - Matrix3::Identity();
  return 0.5 * (H + H.transpose() + H.transpose() * H);
}

/// Small (engineering) strain ε = sym(F − I).
inline Matrix3 small_strain(const Matrix3& F) {
  const Matrix3 H = F - Matrix3::Identity();
  return 0.5 * (H + H.transpose());
}

// --- Building blocks of the tangents (A(3i+J, 3k+L) ↔ A_iJkL) ---------------------------

/// A_iJkL += c X_iJ Y_kL  (X ⊗ Y).
inline void add_dyadic(Tangent3& A, double c, const Matrix3& X, const Matrix3& Y) {
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int k = 0; k < 3; ++k)
        for (int L = 0; L < 3; ++L) A(3 * i + J, 3 * k + L) += c * X(i, J) * Y(k, L);
}

/// A_iJkL += c X_iL Y_kJ. With X = Y = F⁻ᵀ and c = −1 this is ∂(F⁻ᵀ)/∂F.
inline void add_crossed_dyadic(Tangent3& A, double c, const Matrix3& X, const Matrix3& Y) {
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int k = 0; k < 3; ++k)
        for (int L = 0; L < 3; ++L) A(3 * i + J, 3 * k + L) += c * X(i, L) * Y(k, J);
}

/// A_iJkL += c δ_ik S_JL. With c = 1 this is ∂(F S)/∂F at fixed S.
inline void add_spatial_identity(Tangent3& A, double c, const Matrix3& S) {
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int L = 0; L < 3; ++L) A(3 * i + J, 3 * i + L) += c * S(J, L);
}

/// A_iJkL += c B_ik δ_JL.
inline void add_material_identity(Tangent3& A, double c, const Matrix3& B) {
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      for (int J = 0; J < 3; ++J) A(3 * i + J, 3 * k + J) += c * B(i, k);
}

/// The small-strain elasticity tensor as a 9×9 tangent:
/// C_iJkL = λ δ_iJ δ_kL + μ (δ_ik δ_JL + δ_iL δ_Jk) [Pa]. Every law here reduces to it at
/// F = I (with λ = κ − 2μ/3 for the laws written with a bulk modulus κ).
inline Tangent3 isotropic_elasticity_tensor(double lambda, double mu) {
  Tangent3 A = Tangent3::Zero();
  const Matrix3 I = Matrix3::Identity();
  add_dyadic(A, lambda, I, I);
  add_spatial_identity(A, mu, I);
  add_crossed_dyadic(A, mu, I, I);
  return A;
}

// --- Stress measures ---------------------------------------------------------------------

/// Cauchy stress σ = J⁻¹ P Fᵀ [Pa] from the first Piola–Kirchhoff stress P [Pa] and F.
/// For a finite-strain law it is symmetric to round-off (balance of angular momentum).
inline Matrix3 cauchy_from_first_piola(const Matrix3& P, const Matrix3& F) {
  return P * F.transpose() / volume_ratio(F).J;
}

/// Von Mises equivalent stress √(3/2 s:s), s = dev σ, of a Cauchy stress σ [Pa]. Uses
/// sym σ, so round-off asymmetry does not count. Uniaxial σ₁₁ gives |σ₁₁|, pure shear τ
/// gives √3 τ, a hydrostatic stress 0.
inline double von_mises(const Matrix3& sigma) {
  const Matrix3 symmetric = 0.5 * (sigma + sigma.transpose());
  const Matrix3 deviator = symmetric - symmetric.trace() / 3.0 * Matrix3::Identity();
  return std::sqrt(1.5 * deviator.squaredNorm());
}

}  // namespace coapt::solid
