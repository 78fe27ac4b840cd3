#pragma once
// What a probe history ended as: a steady value, a periodic state (mean, amplitude and
// frequency over its last whole periods, with how many), or still changing. Used by
// `fsi run` for the final values it prints and writes to summary.json ("statistics").
//
// Per history (t increasing, y):
//  - periodic: the second half of the history holds at least `min_periods` whole periods
//    (upward crossings of its midrange, re-armed only after falling 10 % of its range below
//    it, as in Turek & Hron's statistics). Over the last `max_periods` of them: mean = time
//    average (trapezoidal), amplitude = (max - min) / 2, frequency = periods / duration, and
//    amplitude_change = (last period's amplitude - first period's) / first period's.
//  - steady: over the last 10 % of the history (at least 2 samples), max - min is at most
//    `steady_tolerance` x max |y| over the whole history (or y never changes).
//  - changing: neither; `periods` says how many whole periods the second half holds (fewer
//    than min_periods: a mean / amplitude / frequency over them would not mean much).
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace fsi {

struct HistoryStats {
  enum class Kind { Steady, Periodic, Changing };
  Kind kind = Kind::Changing;
  double final_value = 0;
  double final_time = 0;
  double change = 0;  // max - min over the last 10 % of the history
  // periodic only (periods is set for Changing too: the whole periods found, < min_periods)
  int periods = 0;
  double t0 = 0, t1 = 0;
  double mean = 0, amplitude = 0, frequency = 0, amplitude_change = 0;
};

struct HistoryStatsOptions {
  int min_periods = 3;
  int max_periods = 4;
  double hysteresis = 0.1;
  double steady_tolerance = 1e-4;
};

const char* to_string(HistoryStats::Kind kind);

// Upward crossings of `level` (y[i-1] < level <= y[i]), linearly interpolated; with
// hysteresis h > 0 a crossing counts only once y fell below level - h since the last one.
std::vector<double> upward_crossings(const std::vector<double>& t, const std::vector<double>& y, double level,
                                     double hysteresis);

// Throws std::invalid_argument for empty or differently sized t and y.
HistoryStats history_stats(const std::vector<double>& t, const std::vector<double>& y,
                           const HistoryStatsOptions& options = {});

nlohmann::json to_json(const HistoryStats& s);
// One line: "steady", "periodic over the last 4 periods ...", "still changing ...".
std::string describe(const HistoryStats& s);

// A CSV of numbers with a header row (probes.csv): the columns by name, in file order.
struct CsvTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  const std::vector<double>* column(const std::string& name) const;
};
CsvTable read_csv_table(const std::filesystem::path& path);

}  // namespace fsi
