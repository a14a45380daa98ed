#include "coapt/lumped/windkessel.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "coapt/core/checks.hpp"
#include "coapt/core/error.hpp"

namespace coapt::lumped {

namespace {

void require_valid_dt(double dt) {
  if (!std::isfinite(dt) || !(dt > 0.0))
    throw InputError(
        fmt::format("Windkessel: the time step dt = {} s must be positive and finite", dt));
}

}  // namespace

void WindkesselParameters::validate(std::string_view where) const {
  require_positive(where, "proximal_resistance", proximal_resistance, "Pa·s/m³");
  require_positive(where, "compliance", compliance, "m³/Pa");
  require_positive(where, "distal_resistance", distal_resistance, "Pa·s/m³");
  require_finite(where, "distal_pressure", distal_pressure, "Pa");
  require_finite(where, "initial_pressure", initial_pressure, "Pa");
}

Windkessel::Windkessel(const WindkesselParameters& parameters, TimeOrder order, double start_time)
    : parameters_(parameters),
      order_(order),
      time_constant_(parameters.distal_resistance * parameters.compliance),
      pc_current_(parameters.initial_pressure),
      pc_previous_(parameters.initial_pressure),
      time_(start_time) {
  parameters_.validate();
  if (order != TimeOrder::first && order != TimeOrder::second)
    throw InputError(
        fmt::format("Windkessel: time order {} is not 1 or 2", static_cast<int>(order)));
  if (!std::isfinite(start_time))
    throw InputError(fmt::format("Windkessel: start time {} s must be finite", start_time));
  if (!(time_constant_ > 0.0) || !std::isfinite(time_constant_))
    throw InputError(fmt::format(
        "Windkessel: the time constant distal_resistance·compliance = {} s is not a positive "
        "finite number (the parameters are out of range)",
        time_constant_));
}

int Windkessel::next_step_order() const {
  return (order_ == TimeOrder::second && step_count_ > 0) ? 2 : 1;
}

Windkessel::Weights Windkessel::weights(double dt) const {
  if (next_step_order() == 1) return {1.0, 1.0, 0.0};
  // Variable-step BDF2 (method/notes.md): ω = Δt_n/Δt_{n−1},
  // u̇ⁿ⁺¹ ≈ [(1+2ω)/(1+ω) uⁿ⁺¹ − (1+ω) uⁿ + ω²/(1+ω) uⁿ⁻¹] / Δt_n.
  const double omega = dt / last_dt_;
  return {(1.0 + 2.0 * omega) / (1.0 + omega), 1.0 + omega, omega * omega / (1.0 + omega)};
}

ImplicitRelation Windkessel::relation(double dt) const {
  require_valid_dt(dt);
  const auto [a0, a1, a2] = weights(dt);
  const double history = a1 * pc_current_ - a2 * pc_previous_;  // h
  const double denominator = a0 * time_constant_ + dt;          // a₀τ + Δt
  return {parameters_.proximal_resistance + parameters_.distal_resistance * dt / denominator,
          (time_constant_ * history + dt * parameters_.distal_pressure) / denominator};
}

void Windkessel::advance(double flow, double dt) {
  require_valid_dt(dt);
  if (!std::isfinite(flow))
    throw ConvergenceError(
        fmt::format("Windkessel: the outlet flow {} m³/s given to advance() is not finite", flow));
  const auto [a0, a1, a2] = weights(dt);
  const double history = a1 * pc_current_ - a2 * pc_previous_;
  // Eq. (3): P_c⁺ = (R_d Δt Q⁺ + τ h + Δt P_d) / (a₀ τ + Δt).
  const double pc_next = (parameters_.distal_resistance * dt * flow + time_constant_ * history +
                          dt * parameters_.distal_pressure) /
                         (a0 * time_constant_ + dt);
  pc_previous_ = pc_current_;
  pc_current_ = pc_next;
  last_dt_ = dt;
  time_ += dt;
  ++step_count_;
}

std::vector<double> Windkessel::state() const {
  return {kStateVersion, static_cast<double>(step_count_), time_, last_dt_, pc_current_,
          pc_previous_};
}

void Windkessel::restore(const std::vector<double>& state) {
  if (state.size() != kStateSize)
    throw InputError(fmt::format(
        "Windkessel checkpoint: the state has {} entries, expected {} (version {}); it was not "
        "written by this Windkessel",
        state.size(), kStateSize, kStateVersion));
  if (state[0] != kStateVersion)
    throw InputError(fmt::format("Windkessel checkpoint: state version {} is not the supported {}",
                                 state[0], kStateVersion));
  const double steps = state[1];
  const double time = state[2];
  const double last_dt = state[3];
  const double pc_current = state[4];
  const double pc_previous = state[5];
  if (!std::isfinite(steps) || steps < 0.0 || steps != std::floor(steps) || steps > 9.0e15)
    throw InputError(
        fmt::format("Windkessel checkpoint: step count {} is not a non-negative integer", steps));
  if (!std::isfinite(time) || !std::isfinite(pc_current) || !std::isfinite(pc_previous))
    throw InputError("Windkessel checkpoint: time or pressure entries are not finite");
  const bool started = steps > 0.0;
  if (started ? !(std::isfinite(last_dt) && last_dt > 0.0) : last_dt != 0.0)
    throw InputError(
        fmt::format("Windkessel checkpoint: last step size {} s is inconsistent with step count {}",
                    last_dt, steps));
  step_count_ = static_cast<long>(steps);
  time_ = time;
  last_dt_ = last_dt;
  pc_current_ = pc_current;
  pc_previous_ = pc_previous;
}

}  // namespace coapt::lumped
