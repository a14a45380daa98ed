#include "coapt/core/progress.hpp"

#include <algorithm>
#include <cmath>

#include "coapt/core/log.hpp"

namespace coapt {
namespace {

std::string format_duration(double seconds) {
  if (seconds < 60) return fmt::format("{:.1f} s", seconds);
  if (seconds < 3600)
    return fmt::format("{:.0f} min {:02.0f} s", std::floor(seconds / 60), std::fmod(seconds, 60));
  return fmt::format("{:.0f} h {:02.0f} min", std::floor(seconds / 3600),
                     std::fmod(seconds, 3600) / 60);
}

}  // namespace

Progress::Progress(int n_steps, double end_time, double start_time)
    : n_steps_(n_steps),
      end_time_(end_time),
      start_time_(start_time),
      start_(std::chrono::steady_clock::now()) {}

double Progress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::step(int step, double time, const std::string& iterations) {
  const double wall = elapsed();
  // By the simulated time still to go: a driver that shortens its steps (a retried step)
  // takes more steps than planned, and the planned count then says nothing.
  const double done = time - start_time_;
  const double left = done > 0 ? wall / done * std::max(end_time_ - time, 0.0) : 0.0;
  const int total = std::max(n_steps_, step);
  log::info("step {:>{}}/{}  t = {:.6g} / {:.6g} s  {}  wall {}  left ~{}", step,
            std::to_string(total).size(), total, time, end_time_, iterations, format_duration(wall),
            format_duration(left));
}

}  // namespace coapt
