#pragma once
/// @file log.hpp
/// Logging: rank 0 prints to the terminal (and to the run's log.txt once opened);
/// other ranks are silent unless asked. Formatting is fmt's.

#include <spdlog/spdlog.h>

#include <string>

namespace coapt::log {

/// Sets up the "coapt" logger for this rank. Collective only in that every rank calls it.
void initialize(int rank, bool all_ranks_print = false);
/// Adds a file sink (rank 0 only): everything logged from now on also goes to `path`.
void add_file(const std::string& path);
/// Removes the file sinks added by add_file.
void close_files();
/// Sets the level: "debug", "info", "warn", "error".
void set_level(const std::string& level);
/// The project's logger.
spdlog::logger& logger();

template <class... Args>
void info(fmt::format_string<Args...> format, Args&&... args) {
  logger().info(format, std::forward<Args>(args)...);
}
template <class... Args>
void warn(fmt::format_string<Args...> format, Args&&... args) {
  logger().warn(format, std::forward<Args>(args)...);
}
template <class... Args>
void error(fmt::format_string<Args...> format, Args&&... args) {
  logger().error(format, std::forward<Args>(args)...);
}
template <class... Args>
void debug(fmt::format_string<Args...> format, Args&&... args) {
  logger().debug(format, std::forward<Args>(args)...);
}

}  // namespace coapt::log
