#pragma once
// One logger entry point. Each component asks for its named logger:
//   auto log = fsi::logger("coupler");  log->info("step {} t={:.4f}", n, t);
// Level from the environment variable FSI_LOG_LEVEL (trace, debug, info, warn, error).
#include <spdlog/spdlog.h>

#include <memory>
#include <string>

namespace fsi {
std::shared_ptr<spdlog::logger> logger(const std::string& name);
}
