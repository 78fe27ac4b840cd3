#pragma once
// A run folder's JSON files as the launcher reads and writes them: summary.json (made final when its
// writer could not), the newest checkpoint's manifest.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "fsi/common/config.hpp"

namespace fsi::launcher {

// The JSON in `file`; null when it is missing or does not parse.
nlohmann::json read_json(const std::filesystem::path& file);

// Throws fsi::WriteError naming the file (a full disk); no .tmp is left behind.
void write_json_atomic(const std::filesystem::path& file, const nlohmann::json& j);

// Makes summary.json final when its writer could not: status, reason, and steps equal to
// the rows of probes.csv. Creates it from the scene if the run never wrote one.
void finalize_summary(const std::filesystem::path& out, const fsi::Scene& scene, const std::string& status,
                      const std::string& reason, bool only_if_running);

// The newest complete checkpoint's manifest (null if none), as the coupler finds it.
nlohmann::json newest_checkpoint(const std::filesystem::path& out);

}  // namespace fsi::launcher
