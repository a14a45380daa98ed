#pragma once
/// @file timer.hpp
/// Wall-clock timers per named stage ("assemble", "solve", ...), accumulated over a run.

#include <chrono>
#include <map>
#include <string>

namespace coapt {

/// Accumulates wall time and call counts per stage name. Not thread-safe.
class StageTimers {
 public:
  /// Adds `seconds` to stage `name`.
  void add(const std::string& name, double seconds) {
    auto& entry = stages_[name];
    entry.seconds += seconds;
    entry.calls += 1;
  }
  struct Entry {
    double seconds = 0.0;
    long calls = 0;
  };
  const std::map<std::string, Entry>& stages() const { return stages_; }

 private:
  std::map<std::string, Entry> stages_;
};

/// Times the enclosing scope into one stage of a StageTimers.
class ScopedTimer {
 public:
  ScopedTimer(StageTimers& timers, std::string name)
      : timers_(timers), name_(std::move(name)), start_(std::chrono::steady_clock::now()) {}
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;
  ~ScopedTimer() { timers_.add(name_, seconds_since(start_)); }

  static double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

 private:
  StageTimers& timers_;
  std::string name_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace coapt
