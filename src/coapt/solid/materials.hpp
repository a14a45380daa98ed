#pragma once
/// @file materials.hpp
/// The solid's constitutive laws behind one run-time entry point. Element kernels hold a
/// `Material` (a std::variant of the parameter structs, chosen per region from the case
/// file) and call, per quadrature point,
///
///   energy(material, F, fibres)       ψ [J/m³]
///   first_piola(material, F, fibres)  P = ∂ψ/∂F [Pa], 3×3
///   tangent(material, F, fibres)      A = ∂P/∂F [Pa], 9×9, A(3i+J, 3k+L) = ∂P_iJ/∂F_kL
///   cauchy(material, F, fibres)       σ [Pa], and von_mises(σ) for output
///
/// with `fibres` the element's fibre directions (ignored by the isotropic laws). The
/// plane_strain namespace wraps the same laws for 2D meshes. The laws themselves are in
/// material_isotropic.hpp and material_fibre.hpp; the conventions in material_common.hpp.
/// Everything here is a pure function: thread-safe, no MPI, no allocation.

#include <string_view>
#include <type_traits>
#include <variant>

#include "coapt/solid/material_common.hpp"
#include "coapt/solid/material_fibre.hpp"
#include "coapt/solid/material_isotropic.hpp"

namespace coapt::solid {

/// A constitutive law with its parameters, selected at run time.
using Material = std::variant<LinearElastic, SaintVenantKirchhoff, NeoHookean,
                              NearlyIncompressibleNeoHookean, FibreReinforced>;

namespace detail {
/// True for the laws whose functions take the element's fibre directions.
template <class Law>
inline constexpr bool kUsesFibres = std::is_same_v<std::remove_cvref_t<Law>, FibreReinforced>;
}  // namespace detail

/// Strain energy density ψ(F) [J/m³] (+∞ for J ≤ 0 where the law has ln J).
inline double energy(const Material& material, const Matrix3& F,
                     const FibreDirections& fibres = {}) {
  return std::visit(
      [&](const auto& law) {
        if constexpr (detail::kUsesFibres<decltype(law)>)
          return law.energy(F, fibres);
        else
          return law.energy(F);
      },
      material);
}

/// First Piola–Kirchhoff stress P(F) = ∂ψ/∂F [Pa].
inline Matrix3 first_piola(const Material& material, const Matrix3& F,
                           const FibreDirections& fibres = {}) {
  return std::visit(
      [&](const auto& law) -> Matrix3 {
        if constexpr (detail::kUsesFibres<decltype(law)>)
          return law.first_piola(F, fibres);
        else
          return law.first_piola(F);
      },
      material);
}

/// Consistent tangent A = ∂P/∂F [Pa], A(3i+J, 3k+L) = ∂P_iJ/∂F_kL.
inline Tangent3 tangent(const Material& material, const Matrix3& F,
                        const FibreDirections& fibres = {}) {
  return std::visit(
      [&](const auto& law) -> Tangent3 {
        if constexpr (detail::kUsesFibres<decltype(law)>)
          return law.tangent(F, fibres);
        else
          return law.tangent(F);
      },
      material);
}

/// Cauchy stress σ [Pa]: J⁻¹ P Fᵀ for the finite-strain laws; for LinearElastic the
/// small-strain stress σ(ε) itself (J⁻¹ P Fᵀ of a small-strain law is neither symmetric nor
/// a better approximation).
inline Matrix3 cauchy(const Material& material, const Matrix3& F,
                      const FibreDirections& fibres = {}) {
  if (const auto* linear = std::get_if<LinearElastic>(&material)) return linear->first_piola(F);
  return cauchy_from_first_piola(first_piola(material, F, fibres), F);
}

/// Checks the parameters (InputError naming `<where>.<parameter>`).
void validate(const Material& material, std::string_view where = "material");
/// Checks an element's fibre directions against the material (unit vectors for each family
/// it uses); nothing to check for isotropic laws. `where` names the element in the message.
void validate_fibres(const Material& material, const FibreDirections& fibres,
                     std::string_view where = "fibres");
/// The law's name as written in case files: "linear_elastic", "saint_venant_kirchhoff",
/// "neo_hookean", "nearly_incompressible_neo_hookean", "fibre_reinforced".
std::string_view name(const Material& material);

/// Homogeneous uniaxial Cauchy stress of the fibre-reinforced law (closed form): the body is
/// stretched by λ along the unit `axis` with free lateral faces, F = λ e⊗e + t (I − e⊗e).
/// The lateral stretch t solves the closed-form lateral stress
///   σ_⊥ = −μ/3 J^{−5/3} (λ² − t²) + κ (J − 1/J)/2 = 0,  J = λ t²,
/// (by bisection), and then
///   σ_∥ = μ J^{−5/3} (λ² − t²) + Σ_{f along e} 2 ψ_f'(λ²) λ²/J,
/// ψ_f'(I₄) = k₁ (I₄ − 1) exp(k₂ (I₄ − 1)²) for I₄ > 1, else 0. Every fibre family must lie
/// along the axis or across it; a family across it must stay slack (λ ≥ 1, so t ≤ 1), which
/// keeps the state transversely isotropic. InputError (naming `where`) otherwise.
struct UniaxialState {
  double stress = 0;           ///< σ_∥ [Pa]
  double lateral_stretch = 1;  ///< t [-]
};
UniaxialState uniaxial_state(const FibreReinforced& law, const FibreDirections& fibres,
                             const Vector3& axis, double stretch,
                             std::string_view where = "uniaxial");

/// Plane strain: a 2×2 F is embedded as diag(F, 1) (F₃₃ = 1, no out-of-plane shear) and the
/// 3D law is evaluated; P and A are its in-plane parts. Energies are per unit volume (per
/// unit thickness and area). Fibre directions must lie in the x–y plane.
namespace plane_strain {

/// The 3×3 deformation gradient diag(F, 1).
inline Matrix3 embed(const Matrix2& F) {
  Matrix3 F3 = Matrix3::Identity();
  F3.topLeftCorner<2, 2>() = F;
  return F3;
}

/// ψ(diag(F, 1)) [J/m³].
inline double energy(const Material& material, const Matrix2& F,
                     const FibreDirections& fibres = {}) {
  return solid::energy(material, embed(F), fibres);
}

/// In-plane P_iJ (i, J < 2) [Pa]; equal to ∂ψ/∂F for the 2×2 F.
inline Matrix2 first_piola(const Material& material, const Matrix2& F,
                           const FibreDirections& fibres = {}) {
  return solid::first_piola(material, embed(F), fibres).topLeftCorner<2, 2>();
}

/// In-plane tangent A(2i+J, 2k+L) = ∂P_iJ/∂F_kL (i, J, k, L < 2) [Pa].
inline Tangent2 tangent(const Material& material, const Matrix2& F,
                        const FibreDirections& fibres = {}) {
  const Tangent3 A = solid::tangent(material, embed(F), fibres);
  Tangent2 A2;
  for (int i = 0; i < 2; ++i)
    for (int J = 0; J < 2; ++J)
      for (int k = 0; k < 2; ++k)
        for (int L = 0; L < 2; ++L) A2(2 * i + J, 2 * k + L) = A(3 * i + J, 3 * k + L);
  return A2;
}

/// The full 3×3 Cauchy stress [Pa], including the out-of-plane σ₃₃ that plane strain
/// produces; von_mises() of it is the plane-strain von Mises stress.
inline Matrix3 cauchy(const Material& material, const Matrix2& F,
                      const FibreDirections& fibres = {}) {
  return solid::cauchy(material, embed(F), fibres);
}

}  // namespace plane_strain

}  // namespace coapt::solid
