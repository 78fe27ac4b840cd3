#include "final_values.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <vector>

#include "fsi/common/history_stats.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/write_check.hpp"

namespace fs = std::filesystem;

namespace fsi::launcher {
namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// Columns a user does not look at first: the coupling's bookkeeping and the solvers'
// iteration counts and mesh diagnostics (still in summary.json's statistics).
bool diagnostic(const std::string& name) {
  return name.rfind("coupling.", 0) == 0 || ends_with(name, "iterations") || ends_with(name, "nonlinear_change") ||
         ends_with(name, "factorisations") || name.find(".mesh_") != std::string::npos;
}

}  // namespace

void report_final_values(const fs::path& out) {
  try {
    const fs::path probes = out / "probes.csv";
    if (!fs::exists(probes)) return;
    const CsvTable table = read_csv_table(probes);
    const auto* time = table.column("time");
    if (!time || time->empty()) return;
    nlohmann::json stats = nlohmann::json::object();
    std::vector<std::pair<std::string, HistoryStats>> shown;
    for (std::size_t i = 0; i < table.names.size(); ++i) {
      const std::string& name = table.names[i];
      if (name == "time") continue;
      const HistoryStats s = history_stats(*time, table.columns[i]);
      stats[name] = to_json(s);
      if (!diagnostic(name)) shown.emplace_back(name, s);
    }
    std::size_t width = 0;
    for (const auto& [name, s] : shown) width = std::max(width, name.size());
    std::string text =
        fmt::format("final values at t = {:.6g} ({} steps; statistics in summary.json):\n", time->back(), time->size());
    for (const auto& [name, s] : shown)
      text += fmt::format("  {:<{}}  {:>13.6g}  {}\n", name, width, s.final_value, describe(s));
    if (const auto* its = table.column("coupling.iterations"); its && !its->empty()) {
      double sum = 0, max = 0;
      for (double v : *its) sum += v, max = std::max(max, v);
      text += fmt::format("  coupling iterations per step: mean {:.2f}, max {:.0f}\n", sum / its->size(), max);
    }
    std::cout << text << std::flush;
    // summary.json: add "statistics", replace atomically
    const fs::path summary = out / "summary.json";
    if (!fs::exists(summary)) return;
    nlohmann::json j;
    {
      std::ifstream in(summary);
      j = nlohmann::json::parse(in, nullptr, false);
    }
    if (!j.is_object()) return;
    if (j.contains("statistics") && j["statistics"] == stats) return;  // e.g. a command that ran nothing
    j["statistics"] = std::move(stats);
    write_file_atomic(summary, j.dump(2) + "\n");  // no .tmp left on a full disk
  } catch (const std::exception& e) {
    logger("fsi")->warn("final values of {}: {}", out.string(), e.what());
  }
}

}  // namespace fsi::launcher
