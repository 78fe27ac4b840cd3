#pragma once
// What `fsi run` shows at the end, and `fsi plot`: the final values of a run's probes with
// their statistics (steady value, or mean / amplitude / frequency over the last whole
// periods with how many; fsi/common/history_stats.hpp), and the plots of a run or study
// folder drawn by tools/fsi_plot.py with the Python interpreter the build found.
#include <filesystem>
#include <string>

namespace fsi::launcher {

// Reads OUT/probes.csv, prints the final values of the physical probes (not the solvers'
// iteration counts and diagnostics) with their statistics to stdout, and adds them for every
// column to OUT/summary.json as "statistics". Does nothing without probes; never throws
// (a problem is logged as a warning).
void report_final_values(const std::filesystem::path& out);

// Runs tools/fsi_plot.py on a run or study folder with `python`; returns its exit code.
int plot_folder(const std::filesystem::path& folder, const std::string& python, const std::filesystem::path& self_dir,
                bool quiet = false);

}  // namespace fsi::launcher
