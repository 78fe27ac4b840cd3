#include "fsi/common/log.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>

#include <cstdlib>
#include <mutex>

namespace fsi {

std::shared_ptr<spdlog::logger> logger(const std::string& name) {
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  if (auto existing = spdlog::get(name)) return existing;
  auto log = spdlog::stderr_color_mt(name);
  log->set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  const char* level = std::getenv("FSI_LOG_LEVEL");
  log->set_level(level ? spdlog::level::from_str(level) : spdlog::level::info);
  log->flush_on(spdlog::level::warn);
  return log;
}

}  // namespace fsi
