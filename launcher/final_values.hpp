#pragma once
// What `fsi run` shows at the end, and `fsi plot`: the final values of a run's probes with
// their statistics (steady value, or mean / amplitude / frequency over the last whole
// periods with how many; fsi/common/history_stats.hpp).
#include <filesystem>
#include <string>

namespace fsi::launcher {

// Reads OUT/probes.csv, prints the final values of the physical probes (not the solvers'
// iteration counts and diagnostics) with their statistics to stdout, and adds them for every
// column to OUT/summary.json as "statistics". Does nothing without probes; never throws
// (a problem is logged as a warning).
void report_final_values(const std::filesystem::path& out);

}  // namespace fsi::launcher
