#pragma once
/// @file dynamics.hpp
/// The pieces of the solid's time integration that need no mesh, header-only and pure:
///
///  - the Newmark update for β = 1/4, γ = 1/2 (the trapezoidal rule, "average acceleration";
///    Newmark 1959; Hughes, The Finite Element Method, §9.1), applied dof by dof:
///
///      a_{n+1} = 4/Δt² (u_{n+1} − u_n − Δt v_n) − a_n
///      v_{n+1} = v_n + Δt/2 (a_n + a_{n+1})
///
///    so that M a_{n+1}(u) + f_int(u) − f_ext = 0 is one nonlinear equation in u = u_{n+1}
///    with tangent 4/Δt² M + K(u). For linear f_int = K u and constant f_ext it conserves
///    E = ½ vᵀMv + ½ uᵀKu − f_extᵀu exactly: E_{n+1} − E_n = ½ (u_{n+1} − u_n)ᵀ(r_n + r_{n+1})
///    with r the residual of the equation of motion, which is zero at each converged step.
///  - the summary of an oscillating signal over its last full period (mean, amplitude,
///    frequency), as reported for the unsteady Turek–Hron cases;
///  - the impacts of a body seen in a time series (rebound angles and energy loss, as in the
///    ball-in-a-box benchmark of method/paper.md §3.1).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <utility>
#include <vector>

namespace coapt::solid {

/// Newmark β = 1/4, γ = 1/2 with step Δt [s].
struct Newmark {
  double step = 0;  ///< Δt [s]

  /// 4/Δt² [1/s²]: the mass matrix's factor in the effective tangent 4/Δt² M + K.
  double mass_factor() const { return 4.0 / (step * step); }
  /// a_{n+1} from the new displacement and the old state.
  double acceleration(double u, double u_old, double v_old, double a_old) const {
    return mass_factor() * (u - u_old - step * v_old) - a_old;
  }
  /// v_{n+1} = v_n + Δt/2 (a_n + a_{n+1}).
  double velocity(double v_old, double a_old, double a) const {
    return v_old + 0.5 * step * (a_old + a);
  }
  /// Start of Newton's iteration: u_n + Δt v_n + Δt²/2 a_n (constant acceleration, so that
  /// the predicted a_{n+1} equals a_n).
  double predictor(double u_old, double v_old, double a_old) const {
    return u_old + step * v_old + 0.5 * step * step * a_old;
  }
};

/// Mean, amplitude and frequency of a signal over its last full period.
struct OscillationSummary {
  double mean = std::numeric_limits<double>::quiet_NaN();       ///< (max + min)/2
  double amplitude = std::numeric_limits<double>::quiet_NaN();  ///< (max − min)/2
  double frequency = std::numeric_limits<double>::quiet_NaN();  ///< [Hz], 1/period
  int periods = 0;  ///< full periods found (0: the others are NaN)
};

namespace detail {
/// Vertex of the parabola through (t[i−1], y[i−1]), (t[i], y[i]), (t[i+1], y[i+1]):
/// refines a sampled extremum to {time, value}. Uniform or not, falls back to the sample
/// when the three points are collinear.
inline std::pair<double, double> parabola_vertex(std::span<const double> t,
                                                 std::span<const double> y, std::size_t i) {
  const double t0 = t[i - 1], t1 = t[i], t2 = t[i + 1];
  const double y0 = y[i - 1], y1 = y[i], y2 = y[i + 1];
  // y = y1 + b (τ − t1) + c (τ − t1)² through the three points.
  const double h0 = t0 - t1, h2 = t2 - t1;
  const double s0 = (y0 - y1) / h0, s2 = (y2 - y1) / h2;
  const double c = (s2 - s0) / (h2 - h0);
  const double b = s0 - c * h0;
  if (c == 0.0 || !std::isfinite(c)) return {t1, y1};
  double shift = -b / (2.0 * c);
  if (shift < h0) shift = h0;  // keep the vertex within the three samples
  if (shift > h2) shift = h2;
  return {t1 + shift, y1 + b * shift + c * shift * shift};
}
}  // namespace detail

/// Summary of the last full period of y(t) (times increasing). Periods are delimited by
/// successive upward crossings of the mid-level m = (top + bottom)/2 of the whole record, with
/// hysteresis: a crossing counts only after the signal has been below m − δ, δ = (top −
/// bottom)/4, and is the first sample interval after that going from below m to at or above
/// it, its time interpolated linearly. top and bottom are the extremes of the record's n finite
/// samples after setting aside the ⌊(n − 1)/100⌋ largest and smallest (none below 101
/// samples): a spike of a step or two, such as the first step after a restart with changed
/// options, must not lift the level out of the oscillation's reach. Crossings, where the
/// signal is steep, are timed far more robustly than flat crests, which small higher-mode
/// wiggles shift by whole samples. The last full period is [t_k−1, t_k] between the last two
/// crossings: the frequency is 1/(t_k − t_k−1), mean and amplitude come from the largest and
/// smallest samples in it, each refined by a parabola through it and its two neighbours.
inline OscillationSummary last_period(std::span<const double> t, std::span<const double> y) {
  OscillationSummary summary;
  const std::size_t n = std::min(t.size(), y.size());
  if (n < 5) return summary;
  std::vector<double> sorted;  // the finite samples (sorting a NaN is undefined)
  for (std::size_t i = 0; i < n; ++i)
    if (std::isfinite(y[i])) sorted.push_back(y[i]);
  if (sorted.size() < 5) return summary;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t set_aside = (sorted.size() - 1) / 100;
  const double top = sorted[sorted.size() - 1 - set_aside], bottom = sorted[set_aside];
  const double level = 0.5 * (top + bottom), band = 0.25 * (top - bottom);
  if (!(band > 0.0)) return summary;
  std::vector<double> crossings;
  std::vector<std::size_t> crossing_index;  // the sample at or above the level
  bool armed = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (y[i] < level - band) armed = true;
    if (armed && i > 0 && y[i - 1] < level && y[i] >= level) {
      const double fraction = (level - y[i - 1]) / (y[i] - y[i - 1]);
      crossings.push_back(t[i - 1] + fraction * (t[i] - t[i - 1]));
      crossing_index.push_back(i);
      armed = false;
    }
  }
  if (crossings.size() < 2) return summary;
  summary.periods = static_cast<int>(crossings.size()) - 1;
  const std::size_t first = crossing_index[crossing_index.size() - 2] - 1;
  const std::size_t last = crossing_index.back();
  std::size_t highest = first, lowest = first;
  for (std::size_t i = first; i <= last; ++i) {
    if (y[i] > y[highest]) highest = i;
    if (y[i] < y[lowest]) lowest = i;
  }
  const auto refined = [&](std::size_t i) {
    return i > 0 && i + 1 < n ? detail::parabola_vertex(t, y, i).second : y[i];
  };
  const double high = refined(highest), low = refined(lowest);
  summary.mean = 0.5 * (high + low);
  summary.amplitude = 0.5 * (high - low);
  summary.frequency = 1.0 / (crossings.back() - crossings[crossings.size() - 2]);
  return summary;
}

/// One impact of a body: the steps [start, end) in contact, the angles of the barycentre
/// velocity with the wall before and after it, and the total energy around it.
struct Impact {
  double start_time = 0;       ///< first time in contact [s]
  double end_time = 0;         ///< first time out of contact again [s]
  double incidence_angle = 0;  ///< angle of the velocity before, with the wall [degrees]
  double rebound_angle = 0;    ///< angle of the velocity after, with the wall [degrees]
  double energy_before = 0;    ///< total energy at the last step before contact
  double energy_after = 0;     ///< total energy at the first step after contact
  double energy_loss = 0;      ///< (before − after) / |before| (negative: energy gained)
};

/// The impacts in a time series: each run of samples with `in_contact` set, preceded and
/// followed by a sample out of contact (a contact still open at the end, or present from the
/// first sample, is not an impact). The wall's normal is taken as the direction of the
/// velocity change v_after − v_before (a frictionless wall pushes only along its normal), and
/// each angle with the wall is asin(|v · n̂| / |v|): 45° in and out for the diamond of the
/// ball in a box. An impact that does not change the velocity is skipped.
inline std::vector<Impact> find_impacts(std::span<const double> times,
                                        std::span<const char> in_contact,
                                        std::span<const std::array<double, 3>> velocity,
                                        std::span<const double> energy) {
  constexpr double kDegrees = 180.0 / 3.14159265358979323846;
  const auto dot = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  };
  const auto angle = [&](const std::array<double, 3>& v, const std::array<double, 3>& n) {
    const double speed = std::sqrt(dot(v, v));
    return speed > 0 ? std::asin(std::min(1.0, std::abs(dot(v, n)) / speed)) * kDegrees : 0.0;
  };
  std::vector<Impact> impacts;
  const std::size_t n = times.size();
  for (std::size_t start = 1; start < n; ++start) {
    if (!in_contact[start] || in_contact[start - 1]) continue;
    std::size_t end = start;
    while (end < n && in_contact[end]) ++end;
    if (end == n) break;
    const auto& before = velocity[start - 1];
    const auto& after = velocity[end];
    std::array<double, 3> normal{after[0] - before[0], after[1] - before[1], after[2] - before[2]};
    const double size = std::sqrt(dot(normal, normal));
    if (size > 0) {
      for (double& x : normal) x /= size;
      Impact impact;
      impact.start_time = times[start];
      impact.end_time = times[end];
      impact.incidence_angle = angle(before, normal);
      impact.rebound_angle = angle(after, normal);
      impact.energy_before = energy[start - 1];
      impact.energy_after = energy[end];
      impact.energy_loss = (impact.energy_before - impact.energy_after) /
                           std::max(std::abs(impact.energy_before), 1e-300);
      impacts.push_back(impact);
    }
    start = end;
  }
  return impacts;
}

}  // namespace coapt::solid
