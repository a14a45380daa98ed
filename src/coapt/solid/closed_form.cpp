// Closed-form benchmarks of the solid (closed_form.hpp).
#include "coapt/solid/closed_form.hpp"

#include <fmt/format.h>

#include <cmath>

#include "coapt/core/error.hpp"
#include "coapt/core/log.hpp"

namespace coapt::solid {

namespace {

void write_uniaxial_benchmark(const SolidModel& solid, io::Json& benchmark) {
  const auto& reference = solid.parameters().uniaxial;
  if (!reference.enabled) return;
  if (solid.dim() != 3)
    throw InputError(reference.where + ": a uniaxial stress state needs a 3D mesh");
  const auto& body = solid.parameters().bodies.front();
  FibreReinforced law;
  FibreDirections fibres;
  fibres.a0 = {reference.axis, reference.axis};
  if (const auto* fibre = std::get_if<FibreReinforced>(&body.material)) {
    law = *fibre;
    fibres = body.fibres;
  } else {
    const auto& matrix = std::get<NearlyIncompressibleNeoHookean>(body.material);
    law.shear_modulus = matrix.shear_modulus;
    law.bulk_modulus = matrix.bulk_modulus;
  }
  const auto F_mean = solid.mean_deformation_gradient();
  const auto sigma_mean = solid.mean_cauchy_stress();
  const auto project = [&](const std::array<double, 9>& m, const Vector3& a, const Vector3& b) {
    double sum = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) sum += a(i) * m[3 * i + j] * b(j);
    return sum;
  };
  const Vector3& e = reference.axis;
  const double stretch = project(F_mean, e, e);
  double trace_F = 0;
  for (int i = 0; i < 3; ++i) {
    trace_F += F_mean[4 * i];
  }
  const double lateral = 0.5 * (trace_F - stretch);
  const double axial = project(sigma_mean, e, e);
  double lateral_stress = 0;  // largest |σ| in the plane normal to e
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Vector3 a = Vector3::Zero(), b = Vector3::Zero();
      a(i) = 1;
      b(j) = 1;
      const Vector3 ap = a - a.dot(e) * e, bp = b - b.dot(e) * e;
      lateral_stress = std::max(lateral_stress, std::abs(project(sigma_mean, ap, bp)));
    }
  const auto closed = uniaxial_state(law, fibres, e, stretch, reference.where);
  const double error = std::abs(axial - closed.stress) / std::abs(closed.stress);
  benchmark["stretch"] = stretch;
  benchmark["lateral_stretch"] = lateral;
  benchmark["lateral_stretch_analytic"] = closed.lateral_stretch;
  benchmark["cauchy_stress_axial"] = axial;
  benchmark["cauchy_stress_axial_analytic"] = closed.stress;
  benchmark["cauchy_stress_axial_error"] = error;
  benchmark["cauchy_stress_lateral_max"] = lateral_stress;
  log::info(
      "uniaxial stretch {:.6f}: axial Cauchy stress {:.8e} Pa (closed form {:.8e} Pa, "
      "relative error {:.2e}), lateral stretch {:.8f} (closed form {:.8f})",
      stretch, axial, closed.stress, error, lateral, closed.lateral_stretch);
  if (!reference.reaction_boundary.empty()) {
    const auto reaction = solid.reaction_force(reference.reaction_boundary);
    const double axial_reaction = Vector3(reaction[0], reaction[1], reaction[2]).dot(e);
    benchmark["reaction_force"] = axial_reaction;
    if (reference.reference_area > 0) {
      const double expected = closed.stress * closed.lateral_stretch * closed.lateral_stretch *
                              reference.reference_area;
      benchmark["reaction_force_analytic"] = expected;
      benchmark["reaction_force_error"] = std::abs(axial_reaction - expected) / std::abs(expected);
      log::info("reaction on '{}': {:.8e} N (closed form {:.8e} N)", reference.reaction_boundary,
                axial_reaction, expected);
    }
  }
}

void write_lame_benchmark(const SolidModel& solid, io::Json& benchmark) {
  const auto& reference = solid.parameters().lame;
  if (!reference.enabled) return;
  const auto& parameters = solid.parameters();
  // Small-strain λ, μ of the body's law.
  const double lambda = std::visit(
      [](const auto& law) -> double {
        if constexpr (requires { law.lambda; })
          return law.lambda;
        else
          return law.bulk_modulus - 2.0 / 3.0 * law.shear_modulus;
      },
      parameters.bodies.front().material);
  const double mu = std::visit([](const auto& law) { return law.shear_modulus; },
                               parameters.bodies.front().material);
  const double young = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
  const double poisson = lambda / (2.0 * (lambda + mu));
  const double p = parameters.pressures.front().pressure;
  const double a = reference.inner_radius, b = reference.outer_radius;
  const auto analytic = [&](double r) {
    return (1.0 + poisson) * p * a * a / (young * (b * b - a * a)) *
           ((1.0 - 2.0 * poisson) * r + b * b / r);
  };
  const auto values = solid.probe_values();
  const auto radial = [&](const std::string& name) {
    for (std::size_t k = 0; k < parameters.probes.size(); ++k)
      if (parameters.probes[k].name == name) {
        const auto& X = parameters.probes[k].point;
        const double r = std::hypot(X[0], X[1]);
        return std::pair{r, (values[k][0] * X[0] + values[k][1] * X[1]) / r};
      }
    throw InputError(fmt::format("{}: no probe named '{}'", reference.where, name));
  };
  for (const auto& [which, probe] :
       {std::pair{"inner", reference.inner_probe}, std::pair{"outer", reference.outer_probe}}) {
    const auto [r, u] = radial(probe);
    const double exact = analytic(r);
    const std::string key = fmt::format("radial_displacement_{}", which);
    benchmark[key] = u;
    benchmark[key + "_analytic"] = exact;
    benchmark[key + "_error"] = std::abs(u - exact) / std::abs(exact);
    log::info("{} = {:.8e} m at r = {:g} m (Lame {:.8e} m, relative error {:.3e})", key, u, r,
              exact, std::abs(u - exact) / std::abs(exact));
  }
}

}  // namespace

void write_closed_form_benchmark(const SolidModel& solid, io::Json& benchmark) {
  write_uniaxial_benchmark(solid, benchmark);
  write_lame_benchmark(solid, benchmark);
}

}  // namespace coapt::solid
