#include "fsi/common/log.hpp"

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>

#include "fsi/common/log_file.hpp"

namespace fsi {
namespace {
std::mutex g_mutex;
spdlog::sink_ptr g_file_sink;  // add_log_file(): every logger writes here too
}  // namespace

std::shared_ptr<spdlog::logger> logger(const std::string& name) {
  std::lock_guard lock(g_mutex);
  if (auto existing = spdlog::get(name)) return existing;
  auto log = spdlog::stderr_color_mt(name);
  if (g_file_sink) log->sinks().push_back(g_file_sink);
  log->set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  const char* level = std::getenv("FSI_LOG_LEVEL");
  log->set_level(level ? spdlog::level::from_str(level) : spdlog::level::info);
  log->flush_on(g_file_sink ? spdlog::level::info : spdlog::level::warn);
  return log;
}

void add_log_file(const std::filesystem::path& file) {
  std::lock_guard lock(g_mutex);
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  auto sink = std::make_shared<spdlog::sinks::basic_file_sink_mt>(file.string(), true);
  sink->set_pattern("[%H:%M:%S.%e] [%n] [%l] %v");
  const auto old = g_file_sink;
  g_file_sink = sink;
  spdlog::apply_all([&](const std::shared_ptr<spdlog::logger>& log) {
    auto& sinks = log->sinks();
    if (old) sinks.erase(std::remove(sinks.begin(), sinks.end(), old), sinks.end());
    sinks.push_back(sink);
    log->flush_on(spdlog::level::info);
  });
}

}  // namespace fsi
