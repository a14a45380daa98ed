// Parameter checks and conversions of the constitutive laws (the laws are header-only).
#include "coapt/solid/materials.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "coapt/core/checks.hpp"
#include "coapt/core/error.hpp"

namespace coapt::solid {

namespace {

// μ > 0 and a positive bulk modulus λ + 2μ/3, which together mean −1 < ν < 0.5.
void validate_lame(std::string_view where, double lambda, double mu) {
  require_positive(where, "shear_modulus", mu, "Pa");
  require_finite(where, "lambda", lambda, "Pa");
  if (!(lambda + 2.0 / 3.0 * mu > 0.0))
    throw InputError(
        fmt::format("{}.lambda = {} Pa with shear_modulus = {} Pa gives a negative bulk modulus "
                    "lambda + 2 mu/3 = {} Pa (Poisson ratio nu = {} <= -1)",
                    where, lambda, mu, lambda + 2.0 / 3.0 * mu, lambda / (2.0 * (lambda + mu))));
}

void validate_young_poisson(std::string_view where, double young, double poisson) {
  require_positive(where, "young_modulus", young, "Pa");
  require_finite(where, "poisson_ratio", poisson, "-");
  if (!(poisson > -1.0 && poisson < 0.5))
    throw InputError(
        fmt::format("{}.poisson_ratio = {} must lie in (-1, 0.5) (0.5 is incompressible: use "
                    "nearly_incompressible_neo_hookean with a large bulk modulus)",
                    where, poisson));
}

}  // namespace

LameParameters lame_from_young_poisson(double young, double poisson, std::string_view where) {
  validate_young_poisson(where, young, poisson);
  return {young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)),
          young / (2.0 * (1.0 + poisson))};
}

double bulk_from_young_poisson(double young, double poisson, std::string_view where) {
  validate_young_poisson(where, young, poisson);
  return young / (3.0 * (1.0 - 2.0 * poisson));
}

void LinearElastic::validate(std::string_view where) const {
  validate_lame(where, lambda, shear_modulus);
}

void SaintVenantKirchhoff::validate(std::string_view where) const {
  validate_lame(where, lambda, shear_modulus);
}

void NeoHookean::validate(std::string_view where) const {
  validate_lame(where, lambda, shear_modulus);
}

void NearlyIncompressibleNeoHookean::validate(std::string_view where) const {
  require_positive(where, "shear_modulus", shear_modulus, "Pa");
  require_positive(where, "bulk_modulus", bulk_modulus, "Pa");
}

void FibreReinforced::validate(std::string_view where) const {
  require_positive(where, "shear_modulus", shear_modulus, "Pa");
  require_positive(where, "bulk_modulus", bulk_modulus, "Pa");
  require_non_negative(where, "fibre_k1", fibre_k1, "Pa");
  require_non_negative(where, "fibre_k2", fibre_k2, "-");
  if (n_fibre_families < 1 || n_fibre_families > kMaxFibreFamilies)
    throw InputError(fmt::format("{}.n_fibre_families = {} must be 1 or {}", where,
                                 n_fibre_families, kMaxFibreFamilies));
}

void FibreReinforced::validate_fibres(const FibreDirections& fibres, std::string_view where) const {
  constexpr double tolerance = 1e-6;
  for (int f = 0; f < n_fibre_families; ++f) {
    const Vector3& a0 = fibres.a0[f];
    const double length = a0.norm();
    if (!std::isfinite(length) || !(std::abs(length - 1.0) <= tolerance))
      throw InputError(
          fmt::format("{}: fibre direction {} = ({}, {}, {}) has length {}, not 1 (to {}); fibre "
                      "directions must be unit vectors in the reference configuration",
                      where, f, a0.x(), a0.y(), a0.z(), length, tolerance));
  }
}

void validate(const Material& material, std::string_view where) {
  std::visit([&](const auto& law) { law.validate(where); }, material);
}

void validate_fibres(const Material& material, const FibreDirections& fibres,
                     std::string_view where) {
  if (const auto* fibre_law = std::get_if<FibreReinforced>(&material))
    fibre_law->validate_fibres(fibres, where);
}

std::string_view name(const Material& material) {
  struct Names {
    std::string_view operator()(const LinearElastic&) const { return "linear_elastic"; }
    std::string_view operator()(const SaintVenantKirchhoff&) const {
      return "saint_venant_kirchhoff";
    }
    std::string_view operator()(const NeoHookean&) const { return "neo_hookean"; }
    std::string_view operator()(const NearlyIncompressibleNeoHookean&) const {
      return "nearly_incompressible_neo_hookean";
    }
    std::string_view operator()(const FibreReinforced&) const { return "fibre_reinforced"; }
  };
  return std::visit(Names{}, material);
}

UniaxialState uniaxial_state(const FibreReinforced& law, const FibreDirections& fibres,
                             const Vector3& axis, double stretch, std::string_view where) {
  if (!(stretch > 0.0) || !std::isfinite(stretch))
    throw InputError(fmt::format("{}: stretch {} must be positive", where, stretch));
  const Vector3 e = axis.normalized();
  const double mu = law.shear_modulus, kappa = law.bulk_modulus, l2 = stretch * stretch;
  double fibre_stress_factor = 0;  // Σ over families along e of 2 ψ'(λ²) λ²
  for (int f = 0; f < law.n_fibre_families; ++f) {
    const double cosine = std::abs(fibres.a0[f].normalized().dot(e));
    if (std::abs(cosine - 1.0) < 1e-12) {
      const double strain = l2 - 1.0;
      if (strain > 0.0)
        fibre_stress_factor +=
            2.0 * law.fibre_k1 * strain * std::exp(law.fibre_k2 * strain * strain) * l2;
    } else if (cosine < 1e-12) {
      if (stretch < 1.0)
        throw InputError(fmt::format(
            "{}: fibre family {} across the axis would be stretched by the lateral expansion "
            "(stretch {} < 1): not a uniaxial state of closed form",
            where, f + 1, stretch));
    } else {
      throw InputError(fmt::format(
          "{}: fibre family {} is neither along nor across the stretch axis", where, f + 1));
    }
  }
  const auto lateral_stress = [&](double t) {
    const double J = stretch * t * t;
    return -mu / 3.0 * std::pow(J, -5.0 / 3.0) * (l2 - t * t) + 0.5 * kappa * (J - 1.0 / J);
  };
  // σ_⊥ increases with t from −∞ (J → 0); bracket its root and bisect to round-off.
  double low = 1e-3 / std::sqrt(stretch), high = 1.0 / std::sqrt(stretch);
  while (lateral_stress(low) > 0.0) low *= 0.5;
  while (lateral_stress(high) < 0.0) high *= 2.0;
  for (int iteration = 0; iteration < 200 && high - low > 1e-16 * high; ++iteration) {
    const double middle = 0.5 * (low + high);
    (lateral_stress(middle) < 0.0 ? low : high) = middle;
  }
  const double t = 0.5 * (low + high), J = stretch * t * t;
  return {mu * std::pow(J, -5.0 / 3.0) * (l2 - t * t) + fibre_stress_factor / J, t};
}

}  // namespace coapt::solid
