#pragma once
/// @file windkessel.hpp
/// The 3-element (RCR) Windkessel outlet model, stepped in time so that the fluid can couple
/// it implicitly: for the next step it gives the outlet pressure as an affine function of the
/// outlet flow, P⁺ = R_eff·Q⁺ + offset.
///
/// Model (method/paper.md eq. 12–13, with an optional venous pressure P_d):
///
///     P(t)          = R_p Q(t) + P_c(t)                                      (1)
///     C dP_c/dt     = Q(t) − (P_c(t) − P_d) / R_d                            (2)
///
///  - Q    flow rate out of the fluid domain through the outlet [m³/s] (Q = ∫_Γ u·n, n outward)
///  - P    pressure at the outlet (proximal pressure) [Pa]
///  - P_c  pressure over the compliance (the paper's "distal pressure") [Pa]
///  - P_d  venous (distal reference) pressure, a constant parameter [Pa]
///  - R_p, R_d  proximal and distal resistances [Pa·s/m³],  C  compliance [m³/Pa]
///  - τ = R_d C  the time constant of the RC part [s]
///
/// Time discretisation. Write the BDF approximation of dP_c/dt at t_{n+1} = t_n + Δt as
///
///     dP_c/dt(t_{n+1}) ≈ (a₀ P_c⁺ − h) / Δt,     h = a₁ P_cⁿ − a₂ P_cⁿ⁻¹,
///
///  - BDF1 (backward Euler; the first step, or every step with TimeOrder::first):
///        a₀ = 1, a₁ = 1, a₂ = 0;
///  - variable-step BDF2 (every later step), with ω = Δt_n / Δt_{n−1} the ratio of this step
///    to the last accepted one:
///        a₀ = (1 + 2ω)/(1 + ω),  a₁ = 1 + ω,  a₂ = ω²/(1 + ω);
///    ω = 1 gives the constant-step weights (3, −4, 1)/2. The scheme is zero-stable for
///    ω < 1 + √2 (Grigorieff 1983), the same condition as the fluid's BDF2.
///
/// Inserting it in (2) at t_{n+1} and multiplying by R_d Δt:
///
///     τ (a₀ P_c⁺ − h) = R_d Δt Q⁺ − Δt (P_c⁺ − P_d)
///     ⇒  P_c⁺ = (R_d Δt Q⁺ + τ h + Δt P_d) / (a₀ τ + Δt)                      (3)
///
/// and with (1), P⁺ = R_p Q⁺ + P_c⁺ = R_eff Q⁺ + offset, where
///
///     R_eff  = R_p + R_d Δt / (a₀ τ + Δt)                                    (4)
///     offset = (τ h + Δt P_d) / (a₀ τ + Δt)                                  (5)
///
/// For BDF1 this is R_eff = R_p + Δt R_d/(C R_d + Δt), offset = (C R_d P_cⁿ + Δt P_d)/(C R_d +
/// Δt) (method/notes.md "Windkessel coupled implicitly", plus the P_d term). R_eff > R_p > 0,
/// so the term the outlet adds to the fluid Jacobian, R_eff (∫_Γ φ_i n)(∫_Γ φ_j n)ᵀ, is
/// symmetric positive semi-definite (docs/theory/windkessel.md).
///
/// Use in a time loop: relation(Δt) (or pressure(Q, Δt)) as often as the nonlinear solver
/// needs — it does not change the state, so a rejected step needs no undo — then
/// advance(Q⁺, Δt) once with the converged flow. Plain C++, no MPI: every rank may hold an
/// identical copy and step it with the same (already reduced) flow.

#include <cstddef>
#include <string_view>
#include <vector>

namespace coapt::lumped {

/// Physical parameters of the RCR Windkessel (SI units). Read once, then const.
struct WindkesselParameters {
  double proximal_resistance = 0.0;  ///< R_p [Pa·s/m³], > 0
  double compliance = 0.0;           ///< C [m³/Pa], > 0
  double distal_resistance = 0.0;    ///< R_d [Pa·s/m³], > 0
  double distal_pressure = 0.0;      ///< P_d, venous pressure the distal resistance drains to [Pa]
  double initial_pressure = 0.0;     ///< P_c at the start time [Pa]

  /// Throws coapt::InputError naming the first bad parameter as `<where>.<name>`: R_p, C, R_d
  /// not positive, or any value not finite. `where` is the caller's name for the block
  /// (e.g. the YAML key path "fluid.outlets.aorta.windkessel").
  void validate(std::string_view where = "windkessel") const;
};

/// The outlet pressure at the end of the next step as an affine function of the flow at the
/// end of that step: P⁺ = effective_resistance·Q⁺ + offset.
struct ImplicitRelation {
  double effective_resistance = 0.0;  ///< R_eff = dP⁺/dQ⁺ [Pa·s/m³], eq. (4) of the file comment
  double offset = 0.0;                ///< P⁺ at Q⁺ = 0 [Pa], eq. (5)

  /// P⁺ [Pa] for the flow Q⁺ [m³/s].
  double pressure(double flow) const { return effective_resistance * flow + offset; }
};

/// Order of the time scheme: `second` is BDF1 on the first step and variable-step BDF2 after;
/// `first` is BDF1 on every step (for tests and for a first-order fluid scheme).
enum class TimeOrder { first = 1, second = 2 };

/// An RCR Windkessel with its time history; see the file comment for the equations.
class Windkessel {
 public:
  /// Version tag stored as the first entry of state(); bump it when the layout changes.
  static constexpr double kStateVersion = 1.0;
  /// Number of entries of state(): version, step count, time, last Δt, P_cⁿ, P_cⁿ⁻¹.
  static constexpr std::size_t kStateSize = 6;

  /// Validates `parameters` (InputError naming the bad one) and starts at
  /// P_c = initial_pressure at time `start_time` [s].
  explicit Windkessel(const WindkesselParameters& parameters, TimeOrder order = TimeOrder::second,
                      double start_time = 0.0);

  /// R_eff and offset for a step of size `dt` [s] from the last accepted state. Does not
  /// change the state. Throws InputError if dt is not positive and finite.
  ImplicitRelation relation(double dt) const;

  /// Outlet pressure P⁺ [Pa] at the end of a step of size `dt` [s] with end-of-step flow
  /// `flow` [m³/s]: relation(dt).pressure(flow).
  double pressure(double flow, double dt) const { return relation(dt).pressure(flow); }

  /// Accepts the step of size `dt` [s] with the converged end-of-step flow `flow` [m³/s]:
  /// P_c⁺ from eq. (3), history shifted, time += dt. Throws InputError for a bad dt and
  /// ConvergenceError for a non-finite flow (the state is then unchanged, so the time loop
  /// may retry the step).
  void advance(double flow, double dt);

  /// P_c at the last accepted step [Pa] (the compliance's pressure, not the parameter P_d).
  double distal_pressure_state() const { return pc_current_; }
  /// Time of the last accepted step [s].
  double time() const { return time_; }
  /// Number of accepted steps since the start (restored by restore()).
  long step_count() const { return step_count_; }
  /// Order of the BDF formula the next step uses (1 on the first step or with TimeOrder::first).
  int next_step_order() const;
  /// The parameters the model was built with.
  const WindkesselParameters& parameters() const { return parameters_; }

  /// The complete time state, kStateSize doubles (layout: see kStateSize), for a checkpoint.
  /// Restoring it into a Windkessel with the same parameters and order continues bit for bit.
  std::vector<double> state() const;
  /// Replaces the time state by one from state(). Throws InputError (and keeps the current
  /// state) if the length or version does not match or an entry is inconsistent.
  void restore(const std::vector<double>& state);

 private:
  /// BDF weights (a₀, a₁, a₂) for a step of size dt from the current history.
  struct Weights {
    double a0, a1, a2;
  };
  Weights weights(double dt) const;

  WindkesselParameters parameters_;
  TimeOrder order_;
  double time_constant_;  ///< τ = R_d C [s]
  double pc_current_;     ///< P_cⁿ [Pa]
  double pc_previous_;    ///< P_cⁿ⁻¹ [Pa] (equal to P_cⁿ before the first step)
  double last_dt_ = 0.0;  ///< Δt_{n−1}: size of the last accepted step [s] (0 before any)
  double time_;           ///< t_n [s]
  long step_count_ = 0;   ///< n
};

}  // namespace coapt::lumped
