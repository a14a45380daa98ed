#pragma once
/// @file material_isotropic.hpp
/// The isotropic constitutive laws: linear elastic (small strain), St. Venant–Kirchhoff,
/// compressible Neo-Hookean and nearly incompressible Neo-Hookean. Each is a small parameter
/// struct (SI units, validate() in materials.cpp) with pure member functions of F:
/// energy ψ [J/m³], first Piola–Kirchhoff stress P = ∂ψ/∂F [Pa] and tangent A = ∂P/∂F [Pa]
/// (index convention in material_common.hpp). Energies are written in H = F − I so that they
/// keep their digits at small strain (they are O(|H|²) while F is O(1)).
///
/// Preconditions: det F > 0 for the laws with ln J (the energy is +∞ otherwise, P and A are
/// then NaN); the element layer checks J and reports the element.

#include <limits>
#include <string_view>

#include "coapt/solid/material_common.hpp"

namespace coapt::solid {

/// Young's modulus and Poisson ratio converted to the Lamé constants λ, μ [Pa].
struct LameParameters {
  double lambda = 0.0;  ///< λ = E ν / ((1 + ν)(1 − 2ν)) [Pa]
  double mu = 0.0;      ///< μ = E / (2(1 + ν)) [Pa]
};

/// λ and μ from E [Pa] and ν [-]. Throws coapt::InputError unless E > 0 and −1 < ν < 0.5
/// (`where` names the parameter block in the message).
LameParameters lame_from_young_poisson(double young, double poisson,
                                       std::string_view where = "material");
/// Bulk modulus κ = E / (3(1 − 2ν)) [Pa]; same checks as lame_from_young_poisson.
double bulk_from_young_poisson(double young, double poisson, std::string_view where = "material");

/// Linear elasticity for the stent: ψ = μ ε:ε + λ/2 (tr ε)², ε = sym(F − I), so
/// P = σ(ε) = 2μ ε + λ tr(ε) I and A = C (constant).
///
/// Not objective: a finite rotation Q gives ε(Q) ≠ 0, a spurious stress of order μ θ² for
/// an angle θ. Use it only where rotations stay small (the stent is nearly rigid and held).
struct LinearElastic {
  double lambda = 0.0;         ///< first Lamé constant λ [Pa]
  double shear_modulus = 0.0;  ///< μ [Pa], > 0

  /// From Young's modulus E [Pa] and Poisson ratio ν [-] (checked).
  static LinearElastic from_young_poisson(double young, double poisson,
                                          std::string_view where = "linear_elastic") {
    const LameParameters lame = lame_from_young_poisson(young, poisson, where);
    return {lame.lambda, lame.mu};
  }
  /// Throws coapt::InputError naming `<where>.<parameter>` unless μ > 0 and the bulk modulus
  /// λ + 2μ/3 > 0 (i.e. −1 < ν < 0.5), all finite.
  void validate(std::string_view where = "linear_elastic") const;

  /// ψ [J/m³].
  double energy(const Matrix3& F) const {
    const Matrix3 strain = small_strain(F);
    const double trace = strain.trace();
    return shear_modulus * strain.squaredNorm() + 0.5 * lambda * trace * trace;
  }
  /// P = σ(ε) [Pa].
  Matrix3 first_piola(const Matrix3& F) const {
    const Matrix3 strain = small_strain(F);
    return 2.0 * shear_modulus * strain + lambda * strain.trace() * Matrix3::Identity();
  }
  /// A = C [Pa], independent of F.
  Tangent3 tangent(const Matrix3& /*F*/) const {
    return isotropic_elasticity_tensor(lambda, shear_modulus);
  }
};

/// St. Venant–Kirchhoff: ψ = λ/2 (tr E)² + μ E:E, S = λ tr(E) I + 2μ E, P = F S.
/// Linear elasticity in E: fine for large rotations with small strains; it softens and loses
/// stability in strong compression (ψ stays finite as J → 0), so not for tissue.
struct SaintVenantKirchhoff {
  double lambda = 0.0;         ///< first Lamé constant λ [Pa]
  double shear_modulus = 0.0;  ///< μ [Pa], > 0

  /// From Young's modulus E [Pa] and Poisson ratio ν [-] (checked).
  static SaintVenantKirchhoff from_young_poisson(
      double young, double poisson, std::string_view where = "saint_venant_kirchhoff") {
    const LameParameters lame = lame_from_young_poisson(young, poisson, where);
    return {lame.lambda, lame.mu};
  }
  /// Same checks as LinearElastic::validate.
  void validate(std::string_view where = "saint_venant_kirchhoff") const;

  /// ψ [J/m³].
  double energy(const Matrix3& F) const {
    const Matrix3 E = green_lagrange_strain(F);
    const double trace = E.trace();
    return 0.5 * lambda * trace * trace + shear_modulus * E.squaredNorm();
  }
  /// Second Piola–Kirchhoff stress S = λ tr(E) I + 2μ E [Pa].
  Matrix3 second_piola(const Matrix3& F) const {
    const Matrix3 E = green_lagrange_strain(F);
    return lambda * E.trace() * Matrix3::Identity() + 2.0 * shear_modulus * E;
  }
  /// P = F S [Pa].
  Matrix3 first_piola(const Matrix3& F) const { return F * second_piola(F); }
  /// dP = dF S + F dS with dS = λ (F:dF) I + μ (FᵀdF + dFᵀF):
  ///   A_iJkL = δ_ik S_JL + λ F_iJ F_kL + μ (b_ik δ_JL + F_iL F_kJ),  b = F Fᵀ.
  Tangent3 tangent(const Matrix3& F) const {
    Tangent3 A = Tangent3::Zero();
    add_spatial_identity(A, 1.0, second_piola(F));
    add_dyadic(A, lambda, F, F);
    add_material_identity(A, shear_modulus, F * F.transpose());
    add_crossed_dyadic(A, shear_modulus, F, F);
    return A;
  }
};

/// Compressible Neo-Hookean: ψ = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)², I₁ = tr C.
///   P = μ (F − F⁻ᵀ) + λ ln J F⁻ᵀ.
struct NeoHookean {
  double lambda = 0.0;         ///< first Lamé constant λ [Pa]
  double shear_modulus = 0.0;  ///< μ [Pa], > 0

  /// From Young's modulus E [Pa] and Poisson ratio ν [-] (checked).
  static NeoHookean from_young_poisson(double young, double poisson,
                                       std::string_view where = "neo_hookean") {
    const LameParameters lame = lame_from_young_poisson(young, poisson, where);
    return {lame.lambda, lame.mu};
  }
  /// Same checks as LinearElastic::validate.
  void validate(std::string_view where = "neo_hookean") const;

  /// ψ [J/m³], +∞ for J ≤ 0. Written without O(|H|) terms that cancel: with
  /// I₁ − 3 = 2 tr H + |H|², ln J = (J − 1) − f(J − 1), f(x) = x − log1p(x) and
  /// J − 1 = tr H + I₂(H) + I₃(H),
  ///   ψ = μ/2 |H|² − μ (I₂ + I₃) + μ f(J − 1) + λ/2 (ln J)².
  double energy(const Matrix3& F) const {
    const VolumeRatio volume = volume_ratio(F);
    if (!(volume.J > 0.0)) return std::numeric_limits<double>::infinity();
    const Matrix3 H = F - Matrix3::Identity();
    return 0.5 * shear_modulus * H.squaredNorm() - shear_modulus * second_plus_third_invariant(H) +
           shear_modulus * x_minus_log1p(volume.J_minus_one) +
           0.5 * lambda * volume.log_J * volume.log_J;
  }
  /// P [Pa].
  Matrix3 first_piola(const Matrix3& F) const {
    const Matrix3 F_inv_T = F.inverse().transpose();
    return shear_modulus * (F - F_inv_T) + lambda * volume_ratio(F).log_J * F_inv_T;
  }
  /// With ∂ ln J/∂F = F⁻ᵀ and ∂(F⁻ᵀ)_iJ/∂F_kL = −F⁻ᵀ_iL F⁻ᵀ_kJ:
  ///   A_iJkL = μ δ_ik δ_JL + λ F⁻ᵀ_iJ F⁻ᵀ_kL + (μ − λ ln J) F⁻ᵀ_iL F⁻ᵀ_kJ.
  Tangent3 tangent(const Matrix3& F) const {
    const Matrix3 F_inv_T = F.inverse().transpose();
    const double log_J = volume_ratio(F).log_J;
    Tangent3 A = Tangent3::Zero();
    add_spatial_identity(A, shear_modulus, Matrix3::Identity());
    add_dyadic(A, lambda, F_inv_T, F_inv_T);
    add_crossed_dyadic(A, shear_modulus - lambda * log_J, F_inv_T, F_inv_T);
    return A;
  }
};

/// Nearly incompressible Neo-Hookean with the isochoric/volumetric split:
///   ψ = μ/2 (Ī₁ − 3) + κ U(J),  Ī₁ = J^{−2/3} I₁,  U(J) = (J² − 1)/4 − (ln J)/2.
///
/// Choice of U (Simo & Taylor 1991, "Quasi-incompressible finite elasticity in principal
/// stretches"): like (J − 1)²/2 it has U(1) = U'(1) = 0 and U''(1) = 1, so κ is the
/// small-strain bulk modulus, but it also grows without bound as J → 0⁺ (U → +∞), so
/// compressing an element to zero volume costs infinite energy, while (J − 1)²/2 stays at
/// 1/2 and lets a Newton iterate invert elements under the large pressures of a closing
/// valve. Its Kirchhoff pressure J U'(J) = (J² − 1)/2 is a polynomial, which keeps the
/// tangent simple. The isochoric part alone gives no pressure: tr(J⁻¹ P_iso Fᵀ) = 0.
///
///   P = μ J^{−2/3} (F − I₁/3 F⁻ᵀ) + κ (J² − 1)/2 F⁻ᵀ,  Cauchy pressure −κ U'(J) =
///   −κ (J − 1/J)/2 under pure dilatation.
struct NearlyIncompressibleNeoHookean {
  double shear_modulus = 0.0;  ///< μ [Pa], > 0
  double bulk_modulus = 0.0;   ///< κ [Pa], > 0 (κ ≫ μ for near incompressibility)

  /// μ and κ from Young's modulus E [Pa] and Poisson ratio ν [-] (checked; ν < 0.5).
  static NearlyIncompressibleNeoHookean from_young_poisson(
      double young, double poisson, std::string_view where = "nearly_incompressible_neo_hookean") {
    return {lame_from_young_poisson(young, poisson, where).mu,
            bulk_from_young_poisson(young, poisson, where)};
  }
  /// Throws coapt::InputError naming `<where>.<parameter>` unless μ > 0 and κ > 0, finite.
  void validate(std::string_view where = "nearly_incompressible_neo_hookean") const;

  /// Volumetric energy U(J) [-] from the volume ratio, as U = (J − 1)²/4 + f(J − 1)/2 with
  /// f(x) = x − log1p(x) (the O(J − 1) terms of (J² − 1)/4 and −(ln J)/2 cancel exactly).
  static double volumetric_energy(const VolumeRatio& volume) {
    const double x = volume.J_minus_one;
    return 0.25 * x * x + 0.5 * x_minus_log1p(x);
  }
  /// U'(J) = (J − 1/J)/2 [-]: the Cauchy stress of a pure dilatation is κ U'(J) I.
  static double volumetric_energy_derivative(double J) { return 0.5 * (J - 1.0 / J); }

  /// ψ [J/m³], +∞ for J ≤ 0. The isochoric measure is formed without cancellation:
  /// Ī₁ − 3 = J^{−2/3} [(I₁ − 3) − 3 (J^{2/3} − 1)], and with x = (2/3) ln J,
  /// 3 (J^{2/3} − 1) = 2 ln J + 3 g(x), g(x) = eˣ − 1 − x, so
  ///   Ī₁ − 3 = J^{−2/3} [ |H|² − 2 (I₂ + I₃) + 2 f(J − 1) − 3 g(x) ],
  /// every term O(|H|²).
  double energy(const Matrix3& F) const {
    const VolumeRatio volume = volume_ratio(F);
    if (!(volume.J > 0.0)) return std::numeric_limits<double>::infinity();
    const Matrix3 H = F - Matrix3::Identity();
    const double x = 2.0 / 3.0 * volume.log_J;
    const double isochoric_I1_minus_3 =
        std::exp(-x) * (H.squaredNorm() - 2.0 * second_plus_third_invariant(H) +
                        2.0 * x_minus_log1p(volume.J_minus_one) - 3.0 * expm1_minus_x(x));
    return 0.5 * shear_modulus * isochoric_I1_minus_3 + bulk_modulus * volumetric_energy(volume);
  }
  /// P [Pa], see the struct comment.
  Matrix3 first_piola(const Matrix3& F) const {
    const VolumeRatio volume = volume_ratio(F);
    const Matrix3 F_inv_T = F.inverse().transpose();
    const double scale = std::exp(-2.0 / 3.0 * volume.log_J);  // J^{-2/3}
    const double I1 = F.squaredNorm();
    const double kirchhoff_pressure = 0.5 * volume.J_minus_one * (2.0 + volume.J_minus_one);
    return shear_modulus * scale * (F - I1 / 3.0 * F_inv_T) +
           bulk_modulus * kirchhoff_pressure * F_inv_T;
  }
  /// With a = J^{−2/3}, ∂a/∂F = −2/3 a F⁻ᵀ, ∂I₁/∂F = 2F, G = F⁻ᵀ, p = (J² − 1)/2, J p' = J²:
  ///   A_iso = μ a [δ_ik δ_JL − 2/3 (F_iJ G_kL + G_iJ F_kL) + 2/9 I₁ G_iJ G_kL
  ///               + I₁/3 G_iL G_kJ]
  ///   A_vol = κ [J² G_iJ G_kL − p G_iL G_kJ].
  Tangent3 tangent(const Matrix3& F) const {
    const VolumeRatio volume = volume_ratio(F);
    const Matrix3 G = F.inverse().transpose();
    const double scale = std::exp(-2.0 / 3.0 * volume.log_J);
    const double I1 = F.squaredNorm();
    const double kirchhoff_pressure = 0.5 * volume.J_minus_one * (2.0 + volume.J_minus_one);
    const double mu_a = shear_modulus * scale;
    Tangent3 A = Tangent3::Zero();
    add_spatial_identity(A, mu_a, Matrix3::Identity());
    add_dyadic(A, -2.0 / 3.0 * mu_a, F, G);
    add_dyadic(A, -2.0 / 3.0 * mu_a, G, F);
    add_dyadic(A, 2.0 / 9.0 * mu_a * I1 + bulk_modulus * volume.J * volume.J, G, G);
    add_crossed_dyadic(A, mu_a * I1 / 3.0 - bulk_modulus * kirchhoff_pressure, G, G);
    return A;
  }
};

}  // namespace coapt::solid
