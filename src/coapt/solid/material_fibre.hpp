#pragma once
/// @file material_fibre.hpp
/// The fibre-reinforced leaflet law, Holzapfel–Gasser–Ogden type: a nearly incompressible
/// Neo-Hookean matrix plus one or two families of collagen fibres that carry load only when
/// stretched,
///
///   ψ = μ/2 (Ī₁ − 3) + κ U(J) + Σ_f ψ_f(I₄f),
///   ψ_f = k₁/(2k₂) (exp(k₂ (I₄f − 1)²) − 1)   if I₄f > 1, else 0,
///   I₄f = a₀f · C a₀f = |F a₀f|²,
///
/// with a₀f the unit fibre direction of family f in the reference configuration (given per
/// element) and the matrix part of NearlyIncompressibleNeoHookean (same U).
///
/// Full I₄, not its isochoric part Ī₄ = J^{−2/3} I₄: with Ī₄ a pure volume change leaves the
/// fibres unloaded, so the anisotropic material would answer a hydrostatic stress with a
/// purely spherical deformation, which is unphysical (Sansour 2008; Helfenstein et al. 2010;
/// shared/method/notes.md "Fibre-reinforced law"). With I₄, stretched fibres resist a
/// dilatation and the stress of F = sI (s > 1) is not spherical (tested).
///
/// Derivatives (ψ' = ∂ψ_f/∂I₄, ψ'' = ∂²ψ_f/∂I₄², e = I₄ − 1 > 0, a = F a₀):
///   ψ'  = k₁ e exp(k₂ e²),   ψ'' = k₁ exp(k₂ e²) (1 + 2 k₂ e²),
///   ∂I₄/∂F = 2 a ⊗ a₀,
///   P_f = 2 ψ' a ⊗ a₀,
///   A_f iJkL = 4 ψ'' a_i a₀J a_k a₀L + 2 ψ' δ_ik a₀J a₀L.
/// Where a fibre crosses I₄ = 1, P is continuous (ψ' = 0 there) but A jumps by
/// 4k₁ (a ⊗ a₀) ⊗ (a ⊗ a₀): a kink of the model, which Newton meets as a change of active set.
/// For large k₂ (I₄ − 1)² the exponential overflows (k₂ e² > 709); P then becomes +∞ and the
/// solid's Newton reports the failure.

#include <array>
#include <string_view>

#include "coapt/solid/material_isotropic.hpp"

namespace coapt::solid {

/// Most fibre families a FibreReinforced material can have.
inline constexpr int kMaxFibreFamilies = 2;

/// Fibre directions of one element in the reference configuration: unit vectors [-]; only
/// the first n_fibre_families of the material are read. Isotropic laws ignore them. In 2D
/// (plane strain) they must lie in the x–y plane.
struct FibreDirections {
  std::array<Vector3, kMaxFibreFamilies> a0{Vector3::Zero(), Vector3::Zero()};
};

/// Parameters of the fibre-reinforced law (see the file comment).
struct FibreReinforced {
  double shear_modulus = 0.0;  ///< matrix μ [Pa], > 0
  double bulk_modulus = 0.0;   ///< κ [Pa], > 0
  double fibre_k1 = 0.0;       ///< fibre stiffness k₁ [Pa], ≥ 0
  double fibre_k2 = 0.0;     ///< fibre stiffening k₂ [-], ≥ 0 (0: ψ_f = k₁/2 (I₄ − 1)²)
  int n_fibre_families = 1;  ///< 1 or 2

  /// Throws coapt::InputError naming `<where>.<parameter>` unless μ, κ > 0, k₁, k₂ ≥ 0
  /// (finite) and n_fibre_families is 1 or 2.
  void validate(std::string_view where = "fibre_reinforced") const;
  /// Throws coapt::InputError unless the first n_fibre_families directions are finite unit
  /// vectors (to 1e-6: a non-unit a₀ would pre-stretch the fibres at F = I). `where` names
  /// the element or field in the message.
  void validate_fibres(const FibreDirections& fibres, std::string_view where = "fibres") const;

  /// The matrix part alone.
  NearlyIncompressibleNeoHookean matrix() const { return {shear_modulus, bulk_modulus}; }

  /// I₄ − 1 = a₀·C a₀ − 1, evaluated as 2 a₀·E a₀ (equal for |a₀| = 1) with E formed from
  /// H = F − I, so that small fibre strains keep their digits and F = I is stress-free even
  /// when a₀ is a unit vector only to round-off. Its F-derivative is 2 F a₀ ⊗ a₀ either way.
  /// Energy, stress and tangent all switch a fibre on by the sign of this one number.
  static double fibre_strain(const Matrix3& green_lagrange, const Vector3& a0) {
    return 2.0 * a0.dot(green_lagrange * a0);
  }

  /// ψ [J/m³], +∞ for J ≤ 0.
  double energy(const Matrix3& F, const FibreDirections& fibres) const {
    double psi = matrix().energy(F);
    const Matrix3 E = green_lagrange_strain(F);
    for (int f = 0; f < n_fibre_families; ++f) {
      const double e = fibre_strain(E, fibres.a0[f]);
      // k₁/(2k₂) expm1(k₂e²) written as k₁/2 e² · expm1(x)/x, x = k₂e², exact also at k₂ = 0.
      if (e > 0.0) psi += 0.5 * fibre_k1 * e * e * expm1_over_x(fibre_k2 * e * e);
    }
    return psi;
  }

  /// P [Pa].
  Matrix3 first_piola(const Matrix3& F, const FibreDirections& fibres) const {
    Matrix3 P = matrix().first_piola(F);
    const Matrix3 E = green_lagrange_strain(F);
    for (int f = 0; f < n_fibre_families; ++f) {
      const Vector3& a0 = fibres.a0[f];
      const double e = fibre_strain(E, a0);
      if (e > 0.0) {
        const double dpsi = fibre_k1 * e * std::exp(fibre_k2 * e * e);
        P += 2.0 * dpsi * (F * a0) * a0.transpose();
      }
    }
    return P;
  }

  /// A = ∂P/∂F [Pa].
  Tangent3 tangent(const Matrix3& F, const FibreDirections& fibres) const {
    Tangent3 A = matrix().tangent(F);
    const Matrix3 E = green_lagrange_strain(F);
    for (int f = 0; f < n_fibre_families; ++f) {
      const Vector3& a0 = fibres.a0[f];
      const double e = fibre_strain(E, a0);
      if (e > 0.0) {
        const double exponential = std::exp(fibre_k2 * e * e);
        const double dpsi = fibre_k1 * e * exponential;
        const double d2psi = fibre_k1 * exponential * (1.0 + 2.0 * fibre_k2 * e * e);
        const Matrix3 dI4 = (F * a0) * a0.transpose();  // ∂I₄/∂F / 2
        add_dyadic(A, 4.0 * d2psi, dI4, dI4);
        add_spatial_identity(A, 2.0 * dpsi, a0 * a0.transpose());
      }
    }
    return A;
  }
};

}  // namespace coapt::solid
