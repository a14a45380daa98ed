#include "coapt/core/log.hpp"

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/null_sink.h>
#include <spdlog/sinks/stdout_sinks.h>

#include <memory>

namespace coapt::log {
namespace {

std::shared_ptr<spdlog::logger>& instance() {
  static std::shared_ptr<spdlog::logger> logger;
  return logger;
}

int& this_rank() {
  static int rank = 0;
  return rank;
}

}  // namespace

void initialize(int rank, bool all_ranks_print) {
  this_rank() = rank;
  std::shared_ptr<spdlog::logger> logger;
  if (rank == 0 || all_ranks_print) {
    auto sink = std::make_shared<spdlog::sinks::stdout_sink_mt>();
    sink->set_pattern(all_ranks_print ? "[rank " + std::to_string(rank) + "] %v" : "%v");
    logger = std::make_shared<spdlog::logger>("coapt", sink);
  } else {
    logger =
        std::make_shared<spdlog::logger>("coapt", std::make_shared<spdlog::sinks::null_sink_mt>());
  }
  logger->set_level(spdlog::level::info);
  logger->flush_on(spdlog::level::info);
  instance() = logger;
}

void add_file(const std::string& path) {
  if (this_rank() != 0) return;
  auto sink = std::make_shared<spdlog::sinks::basic_file_sink_mt>(path, true);
  sink->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] %v");
  logger().sinks().push_back(sink);
}

void close_files() {
  auto& sinks = logger().sinks();
  std::erase_if(sinks, [](const auto& sink) {
    return dynamic_cast<spdlog::sinks::basic_file_sink_mt*>(sink.get()) != nullptr;
  });
}

void set_level(const std::string& level) {
  logger().set_level(spdlog::level::from_str(level));
}

spdlog::logger& logger() {
  if (!instance()) initialize(0);
  return *instance();
}

}  // namespace coapt::log
