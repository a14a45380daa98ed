// Unit tests of the RCR Windkessel (src/coapt/lumped/windkessel.hpp): the implicit relation
// against its closed form, convergence orders against the exact solution for a periodic
// inflow, steady state, checkpoint/restart and input checks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "coapt/core/error.hpp"
#include "coapt/lumped/windkessel.hpp"

namespace {

using coapt::lumped::ImplicitRelation;
using coapt::lumped::TimeOrder;
using coapt::lumped::Windkessel;
using coapt::lumped::WindkesselParameters;

// Physiological orders of magnitude for a human aorta: τ = R_d C = 1.5 s.
WindkesselParameters aortic_parameters() {
  WindkesselParameters p;
  p.proximal_resistance = 1.0e7;  // Pa·s/m³
  p.compliance = 1.0e-8;          // m³/Pa
  p.distal_resistance = 1.5e8;    // Pa·s/m³
  p.distal_pressure = 700.0;      // Pa
  p.initial_pressure = 9000.0;    // Pa, away from the periodic state: a transient is present
  return p;
}

// Inflow Q(t) = Q0 + Q1 sin(Ω t), Ω = 2π/T, and the exact solution of
//   C P_c' = Q − (P_c − P_d)/R_d,  P_c(0) = P_c0,  P = R_p Q + P_c.
// With τ = R_d C, the periodic particular solution is
//   P_c,p(t) = P_d + R_d Q0 + A sin(Ω t) + B cos(Ω t),
//   A = R_d Q1 / (1 + (Ωτ)²),  B = −Ωτ A
// (insert it: the sin terms give A/R_d − CΩB = Q1, the cos terms CΩA + B/R_d = 0), and the
// homogeneous part decays as e^{−t/τ}:
//   P_c(t) = P_c,p(t) + (P_c0 − P_c,p(0)) e^{−t/τ},  P_c,p(0) = P_d + R_d Q0 + B.
struct PeriodicInflow {
  double q0 = 8.0e-5;   // m³/s (≈ 4.8 L/min)
  double q1 = 1.0e-4;   // m³/s
  double period = 0.8;  // s

  double omega() const { return 2.0 * std::numbers::pi / period; }
  double flow(double t) const { return q0 + q1 * std::sin(omega() * t); }

  double exact_pressure(const WindkesselParameters& p, double t) const {
    const double tau = p.distal_resistance * p.compliance;
    const double wt = omega() * tau;
    const double a = p.distal_resistance * q1 / (1.0 + wt * wt);
    const double b = -wt * a;
    const double mean = p.distal_pressure + p.distal_resistance * q0;
    const double particular = mean + a * std::sin(omega() * t) + b * std::cos(omega() * t);
    const double transient = (p.initial_pressure - (mean + b)) * std::exp(-t / tau);
    return p.proximal_resistance * flow(t) + particular + transient;
  }
};

// Runs the Windkessel with the exact inflow over `n_steps` steps, step k of size
// step(k), and returns the largest |P − P_exact| at the step ends. P is taken from the
// implicit relation, as the fluid would see it.
double max_error(TimeOrder order, int n_steps, const std::function<double(int)>& step) {
  const auto parameters = aortic_parameters();
  const PeriodicInflow inflow;
  Windkessel windkessel(parameters, order);
  double t = 0.0;
  double error = 0.0;
  for (int k = 0; k < n_steps; ++k) {
    const double dt = step(k);
    const double q = inflow.flow(t + dt);
    const double p = windkessel.pressure(q, dt);
    windkessel.advance(q, dt);
    t += dt;
    error = std::max(error, std::abs(p - inflow.exact_pressure(parameters, t)));
  }
  EXPECT_NEAR(windkessel.time(), t, 1e-12);
  return error;
}

constexpr int kPeriods = 3;
constexpr int kCoarseStepsPerPeriod = 100;

// Errors on three grids, step h = T/100, T/200, T/400 (8, 4, 2 ms) over 3 periods, and the
// observed orders. (From T/40 the first order is still pre-asymptotic, 1.91.)
struct Study {
  std::vector<double> errors;
  std::vector<double> orders;
};

Study refinement_study(TimeOrder order, const std::function<double(int, double)>& step_of_h) {
  const PeriodicInflow inflow;
  Study study;
  for (int level = 0; level < 3; ++level) {
    const int per_period = kCoarseStepsPerPeriod << level;
    const double h = inflow.period / per_period;
    study.errors.push_back(
        max_error(order, kPeriods * per_period, [&](int k) { return step_of_h(k, h); }));
  }
  for (int i = 1; i < 3; ++i)
    study.orders.push_back(std::log2(study.errors[i - 1] / study.errors[i]));
  return study;
}

void print(const char* name, const Study& study) {
  std::printf(
      "[ windkessel ] %s: max |P - P_exact| = %.3e, %.3e, %.3e Pa; observed orders %.3f, %.3f\n",
      name, study.errors[0], study.errors[1], study.errors[2], study.orders[0], study.orders[1]);
}

TEST(WindkesselRelation, FirstStepIsBackwardEulerClosedForm) {
  const auto p = aortic_parameters();
  const Windkessel windkessel(p);
  const double dt = 1e-3;
  const ImplicitRelation r = windkessel.relation(dt);
  // method/notes.md: R_eff = R_p + Δt R_d/(C R_d + Δt), P₀ = (C R_d P_c + Δt P_d)/(C R_d + Δt).
  const double tau = p.compliance * p.distal_resistance;
  EXPECT_NEAR(r.effective_resistance, p.proximal_resistance + dt * p.distal_resistance / (tau + dt),
              1e-15 * 1e7);
  EXPECT_NEAR(r.offset, (tau * p.initial_pressure + dt * p.distal_pressure) / (tau + dt),
              1e-15 * 1e4);
  EXPECT_EQ(windkessel.next_step_order(), 1);
}

TEST(WindkesselRelation, SecondStepIsConstantStepBdf2ClosedForm) {
  const auto p = aortic_parameters();
  Windkessel windkessel(p);
  const double dt = 2e-3;
  windkessel.advance(1e-4, dt);
  EXPECT_EQ(windkessel.next_step_order(), 2);
  const double pc1 = windkessel.distal_pressure_state();
  const double pc0 = p.initial_pressure;
  // C (3 P_c⁺ − 4 P_c¹ + P_c⁰)/(2Δt) = Q⁺ − (P_c⁺ − P_d)/R_d.
  const double tau = p.compliance * p.distal_resistance;
  const ImplicitRelation r = windkessel.relation(dt);
  EXPECT_NEAR(r.effective_resistance,
              p.proximal_resistance + dt * p.distal_resistance / (1.5 * tau + dt), 1e-15 * 1e7);
  EXPECT_NEAR(r.offset, (tau * (2.0 * pc1 - 0.5 * pc0) + dt * p.distal_pressure) / (1.5 * tau + dt),
              1e-14 * 1e4);
}

TEST(WindkesselRelation, FirstOrderOptionStaysBackwardEuler) {
  Windkessel windkessel(aortic_parameters(), TimeOrder::first);
  windkessel.advance(1e-4, 1e-3);
  windkessel.advance(1e-4, 1e-3);
  EXPECT_EQ(windkessel.next_step_order(), 1);
}

// P from relation(dt) at Q⁺ before the step equals R_p Q⁺ + P_c after advance(Q⁺, dt), on
// BDF1 and BDF2 steps with changing step sizes and both signs of the flow.
TEST(WindkesselRelation, ConsistentWithAdvance) {
  const auto p = aortic_parameters();
  for (const TimeOrder order : {TimeOrder::first, TimeOrder::second}) {
    Windkessel windkessel(p, order);
    const std::vector<double> steps = {1e-3, 1e-3, 2.5e-3, 0.7e-3, 1.9e-3, 1e-2, 4e-3};
    const std::vector<double> flows = {1e-4, 3e-4, -2e-5, 0.0, 5e-4, 1e-6, -1e-4};
    for (std::size_t k = 0; k < steps.size(); ++k) {
      const double predicted = windkessel.pressure(flows[k], steps[k]);
      windkessel.advance(flows[k], steps[k]);
      const double after = p.proximal_resistance * flows[k] + windkessel.distal_pressure_state();
      EXPECT_NEAR(predicted, after, 1e-13 * std::abs(after)) << "step " << k;
    }
    EXPECT_EQ(windkessel.step_count(), static_cast<long>(steps.size()));
  }
}

// Constant steps: BDF1 first, BDF2 after. Asserted: both observed orders ≥ 1.9 and every
// halving of the step divides the max error by ≥ 3.7.
TEST(WindkesselConvergence, SecondOrderOnExactPeriodicSolution) {
  const Study study = refinement_study(TimeOrder::second, [](int, double h) { return h; });
  print("BDF2, constant step", study);
  for (const double order : study.orders) EXPECT_GE(order, 1.9);
  for (int i = 1; i < 3; ++i) EXPECT_GE(study.errors[i - 1] / study.errors[i], 3.7);
  // And small: below 10⁻⁴ of the mean pressure (R_p + R_d) Q0 + P_d = 13.5 kPa at h = 2 ms.
  const auto p = aortic_parameters();
  const double mean_pressure =
      (p.proximal_resistance + p.distal_resistance) * PeriodicInflow{}.q0 + p.distal_pressure;
  EXPECT_LT(study.errors[2], 1e-4 * mean_pressure);
}

// BDF1 on every step. Asserted: observed orders in [0.9, 1.1].
TEST(WindkesselConvergence, FirstOrderWithBackwardEulerOnly) {
  const Study study = refinement_study(TimeOrder::first, [](int, double h) { return h; });
  print("BDF1 only, constant step", study);
  for (const double order : study.orders) {
    EXPECT_GE(order, 0.9);
    EXPECT_LE(order, 1.1);
  }
}

// Alternating steps 2h/3, 4h/3 (ratios ω = 2 and 1/2, inside the zero-stability bound
// 1 + √2), refined by halving h. Asserted: both observed orders ≥ 1.9, as for constant steps.
TEST(WindkesselConvergence, SecondOrderWithAlternatingSteps) {
  const Study study = refinement_study(TimeOrder::second, [](int k, double h) {
    return (k % 2 == 0) ? 2.0 * h / 3.0 : 4.0 * h / 3.0;
  });
  print("BDF2, alternating steps 2h/3, 4h/3", study);
  for (const double order : study.orders) EXPECT_GE(order, 1.9);
}

// Steps that change smoothly, between 0.5h and 1.5h, over a period. Asserted: orders ≥ 1.9.
TEST(WindkesselConvergence, SecondOrderWithSmoothlyVaryingSteps) {
  const Study study = refinement_study(TimeOrder::second, [](int k, double h) {
    // dt_k = h g(k h / T) with g = 1 + sin(2π·)/2: the steps of each period sum to T.
    const double phase = 2.0 * std::numbers::pi * k * h / PeriodicInflow{}.period;
    return h * (1.0 + 0.5 * std::sin(phase));
  });
  print("BDF2, smoothly varying steps", study);
  for (const double order : study.orders) EXPECT_GE(order, 1.9);
}

TEST(WindkesselSteadyState, ConstantFlowGivesTotalResistanceTimesFlowPlusVenousPressure) {
  const auto p = aortic_parameters();
  const double q = 9.0e-5;
  const double expected = (p.proximal_resistance + p.distal_resistance) * q + p.distal_pressure;
  Windkessel windkessel(p);
  const double dt = 0.05;
  double pressure = 0.0;
  for (int k = 0; k < 1200; ++k) {  // 60 s = 40 τ
    pressure = windkessel.pressure(q, dt);
    windkessel.advance(q, dt);
  }
  EXPECT_NEAR(pressure, expected, 1e-11 * expected);

  // Started at equilibrium, it stays there to round-off, whatever the steps.
  auto at_rest = p;
  at_rest.initial_pressure = p.distal_resistance * q + p.distal_pressure;
  Windkessel resting(at_rest);
  for (const double step : {1e-3, 3e-3, 1e-3, 2e-2, 7e-3}) {
    EXPECT_NEAR(resting.pressure(q, step), expected, 1e-14 * expected);
    resting.advance(q, step);
  }
}

// A run interrupted after n steps by state()/restore() into a fresh object continues bit for
// bit like the uninterrupted run, on a BDF2 history with changing steps.
TEST(WindkesselCheckpoint, RestartIsBitIdentical) {
  const auto p = aortic_parameters();
  const PeriodicInflow inflow;
  auto step = [](int k) { return 1e-3 * (1.0 + 0.3 * std::sin(0.7 * k)); };

  for (const int interrupt_at : {0, 1, 7}) {
    Windkessel reference(p);
    Windkessel first_half(p);
    for (int k = 0; k < interrupt_at; ++k) {
      const double q = inflow.flow(reference.time() + step(k));
      reference.advance(q, step(k));
      first_half.advance(q, step(k));
    }
    const std::vector<double> saved = first_half.state();
    ASSERT_EQ(saved.size(), Windkessel::kStateSize);

    Windkessel restarted(p);
    restarted.advance(3e-4, 0.1);  // some other history, overwritten by restore()
    restarted.restore(saved);
    EXPECT_EQ(restarted.state(), saved);
    EXPECT_EQ(restarted.step_count(), interrupt_at);

    for (int k = interrupt_at; k < interrupt_at + 25; ++k) {
      const double q = inflow.flow(reference.time() + step(k));
      const ImplicitRelation a = reference.relation(step(k));
      const ImplicitRelation b = restarted.relation(step(k));
      EXPECT_EQ(a.effective_resistance, b.effective_resistance) << "step " << k;
      EXPECT_EQ(a.offset, b.offset) << "step " << k;
      reference.advance(q, step(k));
      restarted.advance(q, step(k));
      EXPECT_EQ(reference.distal_pressure_state(), restarted.distal_pressure_state());
      EXPECT_EQ(reference.time(), restarted.time());
    }
    EXPECT_EQ(reference.state(), restarted.state());
  }
}

TEST(WindkesselCheckpoint, MismatchedStateThrowsAndKeepsTheState) {
  Windkessel windkessel(aortic_parameters());
  windkessel.advance(1e-4, 1e-3);
  const std::vector<double> good = windkessel.state();

  std::vector<std::vector<double>> bad = {
      {},
      std::vector<double>(good.begin(), good.end() - 1),  // too short
      [&] {
        auto s = good;
        s.push_back(0.0);
        return s;
      }(),  // too long
      [&] {
        auto s = good;
        s[0] = 2.0;
        return s;
      }(),  // unknown version
      [&] {
        auto s = good;
        s[1] = 1.5;
        return s;
      }(),  // non-integer step count
      [&] {
        auto s = good;
        s[1] = -1.0;
        return s;
      }(),  // negative step count
      [&] {
        auto s = good;
        s[3] = 0.0;
        return s;
      }(),  // no last step after a step
      [&] {
        auto s = good;
        s[4] = std::nan("");
        return s;
      }(),
  };
  for (std::size_t i = 0; i < bad.size(); ++i) {
    EXPECT_THROW(windkessel.restore(bad[i]), coapt::InputError) << "case " << i;
    EXPECT_EQ(windkessel.state(), good) << "case " << i;
  }
  try {
    windkessel.restore(std::vector<double>(3, 1.0));
    FAIL() << "no exception";
  } catch (const coapt::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("3 entries, expected 6"), std::string::npos) << e.what();
  }
}

TEST(WindkesselParameters, ValidateNamesTheBadParameter) {
  struct Case {
    std::string name;
    std::function<void(WindkesselParameters&)> spoil;
  };
  const std::vector<Case> cases = {
      {"proximal_resistance", [](auto& p) { p.proximal_resistance = 0.0; }},
      {"proximal_resistance", [](auto& p) { p.proximal_resistance = -1.0e7; }},
      {"compliance", [](auto& p) { p.compliance = 0.0; }},
      {"compliance", [](auto& p) { p.compliance = -1.0e-8; }},
      {"compliance", [](auto& p) { p.compliance = std::nan(""); }},
      {"distal_resistance", [](auto& p) { p.distal_resistance = 0.0; }},
      {"distal_resistance", [](auto& p) { p.distal_resistance = -2.0; }},
      {"distal_resistance", [](auto& p) { p.distal_resistance = HUGE_VAL; }},
      {"distal_pressure", [](auto& p) { p.distal_pressure = std::nan(""); }},
      {"initial_pressure", [](auto& p) { p.initial_pressure = -HUGE_VAL; }},
  };
  EXPECT_NO_THROW(aortic_parameters().validate());
  for (const auto& c : cases) {
    auto p = aortic_parameters();
    c.spoil(p);
    try {
      p.validate("fluid.outlets.aorta.windkessel");
      ADD_FAILURE() << "no exception for " << c.name;
    } catch (const coapt::InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("fluid.outlets.aorta.windkessel." + c.name), std::string::npos)
          << message;
    }
    EXPECT_THROW(Windkessel{p}, coapt::InputError) << c.name;
  }
  // Negative pressures are gauge pressures, not errors.
  auto p = aortic_parameters();
  p.distal_pressure = -500.0;
  p.initial_pressure = -100.0;
  EXPECT_NO_THROW(p.validate());
}

TEST(WindkesselInput, BadStepAndNonFiniteFlowThrow) {
  Windkessel windkessel(aortic_parameters());
  windkessel.advance(1e-4, 1e-3);
  const auto before = windkessel.state();
  for (const double dt : {0.0, -1e-3, std::nan(""), HUGE_VAL}) {
    EXPECT_THROW(windkessel.relation(dt), coapt::InputError) << dt;
    EXPECT_THROW(windkessel.advance(1e-4, dt), coapt::InputError) << dt;
  }
  EXPECT_THROW(windkessel.advance(std::nan(""), 1e-3), coapt::ConvergenceError);
  EXPECT_THROW(windkessel.advance(HUGE_VAL, 1e-3), coapt::ConvergenceError);
  EXPECT_EQ(windkessel.state(), before);
}

}  // namespace
