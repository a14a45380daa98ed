#pragma once
/// @file progress.hpp
/// The progress line of a long run: one line per time step with the step, the time, the
/// solver iterations, the wall time and an estimate of the time left.

#include <chrono>
#include <string>

namespace coapt {

/// Prints (through the log, rank 0) one line per completed step.
class Progress {
 public:
  /// `n_steps` steps (planned) from `start_time` to `end_time` [s] of simulated time.
  Progress(int n_steps, double end_time, double start_time = 0.0);
  /// Reports step `step` (1-based) completed at simulated time `time`; `iterations` is a
  /// short free text ("newton 3, ksp 41"). The time left is estimated from the simulated time
  /// still to go; a step beyond the planned count (a driver that shortened its steps) raises
  /// the count shown.
  void step(int step, double time, const std::string& iterations);
  /// Wall time since construction [s].
  double elapsed() const;

 private:
  int n_steps_;
  double end_time_;
  double start_time_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace coapt
