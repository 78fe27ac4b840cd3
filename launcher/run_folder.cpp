#include "run_folder.hpp"

#include <fstream>

#include "fsi/common/log.hpp"
#include "fsi/common/run_report.hpp"
#include "fsi/common/write_check.hpp"
#include "fsi/coupling/checkpoint.hpp"

namespace fs = std::filesystem;

namespace fsi::launcher {

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return nullptr;
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception&) {
    return nullptr;
  }
}

void write_json_atomic(const fs::path& file, const nlohmann::json& j) {
  fsi::write_file_atomic(file, j.dump(2) + "\n");
}

void finalize_summary(const fs::path& out, const fsi::Scene& scene, const std::string& status,
                      const std::string& reason, bool only_if_running) {
  nlohmann::json j = read_json(out / "summary.json");
  if (j.is_null() || !j.is_object()) {
    fsi::RunReport report(out, scene, "fsi");
    j = report.data();
  } else if (only_if_running && j.value("status", std::string("running")) != "running") {
    return;
  }
  j["status"] = status;
  j["reason"] = reason;
  j["steps"] = fsi::csv_rows(out / "probes.csv");
  try {
    write_json_atomic(out / "summary.json", j);
  } catch (const std::exception& e) {  // a full disk: the status goes to stderr instead
    fsi::logger("fsi")->error("{}; the run's status is not in it: {}: {}", e.what(), status, reason);
  }
}

nlohmann::json newest_checkpoint(const fs::path& out) {
  const auto c = fsi::coupling::CheckpointStore(out / "checkpoints", 1).newest();
  return c ? c->manifest : nlohmann::json(nullptr);
}

}  // namespace fsi::launcher
