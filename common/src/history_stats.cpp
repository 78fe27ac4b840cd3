#include "fsi/common/history_stats.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fsi {
namespace {

// The integral of the piecewise-linear interpolant of (t, y) over [a, b] (inside t's range).
double integral(const std::vector<double>& t, const std::vector<double>& y, double a, double b) {
  const auto at = [&](double x) {
    const auto it = std::upper_bound(t.begin(), t.end(), x);
    if (it == t.begin()) return y.front();
    if (it == t.end()) return y.back();
    const std::size_t i = static_cast<std::size_t>(it - t.begin());
    const double s = (x - t[i - 1]) / (t[i] - t[i - 1]);
    return y[i - 1] + s * (y[i] - y[i - 1]);
  };
  double sum = 0, x0 = a, y0 = at(a);
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i] <= a) continue;
    if (t[i] >= b) break;
    sum += 0.5 * (y0 + y[i]) * (t[i] - x0);
    x0 = t[i], y0 = y[i];
  }
  sum += 0.5 * (y0 + at(b)) * (b - x0);
  return sum;
}

// (max - min) / 2 of the samples with a <= t <= b; 0 when there are none.
double half_range(const std::vector<double>& t, const std::vector<double>& y, double a, double b) {
  double hi = -INFINITY, lo = INFINITY;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] >= a && t[i] <= b) hi = std::max(hi, y[i]), lo = std::min(lo, y[i]);
  return hi >= lo ? 0.5 * (hi - lo) : 0.0;
}

}  // namespace

const char* to_string(HistoryStats::Kind kind) {
  switch (kind) {
    case HistoryStats::Kind::Steady:
      return "steady";
    case HistoryStats::Kind::Periodic:
      return "periodic";
    case HistoryStats::Kind::Changing:
      return "changing";
  }
  return "changing";
}

std::vector<double> upward_crossings(const std::vector<double>& t, const std::vector<double>& y, double level,
                                     double hysteresis) {
  std::vector<double> up;
  bool armed = hysteresis <= 0;
  for (std::size_t i = 1; i < y.size(); ++i) {
    if (y[i - 1] < level - hysteresis) armed = true;
    if (y[i - 1] < level && level <= y[i] && (armed || hysteresis <= 0)) {
      const double s = (level - y[i - 1]) / (y[i] - y[i - 1]);
      up.push_back(t[i - 1] + s * (t[i] - t[i - 1]));
      armed = hysteresis <= 0;
    }
  }
  return up;
}

HistoryStats history_stats(const std::vector<double>& t, const std::vector<double>& y, const HistoryStatsOptions& o) {
  if (t.empty() || t.size() != y.size())
    throw std::invalid_argument(fmt::format("history_stats: {} times and {} values", t.size(), y.size()));
  HistoryStats s;
  const std::size_t n = t.size();
  s.final_value = y.back();
  s.final_time = t.back();
  const double span = t.back() - t.front();
  double scale = 0;
  for (double v : y) scale = std::max(scale, std::abs(v));
  {  // the last 10 % (at least the last 2 samples)
    const double from = t.back() - 0.1 * span;
    double hi = y.back(), lo = y.back();
    for (std::size_t i = n; i-- > 0;) {
      if (t[i] < from && i + 2 < n) break;
      hi = std::max(hi, y[i]), lo = std::min(lo, y[i]);
    }
    s.change = hi - lo;
  }
  // whole periods in the second half
  const double half = t.front() + 0.5 * span;
  std::vector<double> th, yh;
  for (std::size_t i = 0; i < n; ++i)
    if (t[i] >= half) th.push_back(t[i]), yh.push_back(y[i]);
  if (yh.size() >= 4) {
    const auto [lo_it, hi_it] = std::minmax_element(yh.begin(), yh.end());
    const double hi = *hi_it, lo = *lo_it;
    if (hi > lo) {
      std::vector<double> up = upward_crossings(th, yh, 0.5 * (hi + lo), o.hysteresis * (hi - lo));
      s.periods = std::max(0, static_cast<int>(up.size()) - 1);
      // a steady tail that only wobbles at round-off level is steady, not periodic
      const bool steady = s.change <= o.steady_tolerance * scale;
      if (s.periods >= o.min_periods && !steady) {
        const int p = std::min(s.periods, o.max_periods);
        up.erase(up.begin(), up.end() - (p + 1));
        s.kind = HistoryStats::Kind::Periodic;
        s.periods = p;
        s.t0 = up.front(), s.t1 = up.back();
        s.mean = integral(t, y, s.t0, s.t1) / (s.t1 - s.t0);
        s.amplitude = half_range(t, y, s.t0, s.t1);
        s.frequency = p / (s.t1 - s.t0);
        const double first = half_range(t, y, up[0], up[1]), last = half_range(t, y, up[p - 1], up[p]);
        s.amplitude_change = first > 0 ? (last - first) / first : 0.0;
        return s;
      }
    }
  }
  if (s.change <= o.steady_tolerance * scale) s.kind = HistoryStats::Kind::Steady;
  return s;
}

nlohmann::json to_json(const HistoryStats& s) {
  nlohmann::json j{{"kind", to_string(s.kind)}, {"final", s.final_value}, {"time", s.final_time}};
  if (s.kind == HistoryStats::Kind::Periodic) {
    j["periods"] = s.periods;
    j["window"] = {s.t0, s.t1};
    j["mean"] = s.mean;
    j["amplitude"] = s.amplitude;
    j["frequency"] = s.frequency;
    j["amplitude_change"] = s.amplitude_change;
  } else {
    j["change_last_10_percent"] = s.change;
    if (s.kind == HistoryStats::Kind::Changing) j["periods"] = s.periods;
  }
  return j;
}

std::string describe(const HistoryStats& s) {
  switch (s.kind) {
    case HistoryStats::Kind::Steady:
      return fmt::format("steady (change over the last 10 %: {:.2g})", s.change);
    case HistoryStats::Kind::Periodic: {
      std::string d = fmt::format(
          "mean {:.6g}, amplitude {:.4g}, frequency {:.4g} Hz over the last {} periods "
          "[{:.4g}, {:.4g}] s",
          s.mean, s.amplitude, s.frequency, s.periods, s.t0, s.t1);
      if (std::abs(s.amplitude_change) > 0.02)
        d += fmt::format("; amplitude {} {:.0f} % from the first to the last (not settled)",
                         s.amplitude_change > 0 ? "grew" : "fell", 100 * std::abs(s.amplitude_change));
      return d;
    }
    case HistoryStats::Kind::Changing:
      return s.periods > 0 ? fmt::format(
                                 "still changing: {} whole period{} in the second half, fewer than 3 "
                                 "(run longer for a mean, amplitude and frequency)",
                                 s.periods, s.periods == 1 ? "" : "s")
                           : fmt::format("still changing (by {:.2g} over the last 10 %)", s.change);
  }
  return "";
}

const std::vector<double>* CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return &columns[i];
  return nullptr;
}

CsvTable read_csv_table(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read '" + path.string() + "'");
  CsvTable table;
  std::string line;
  if (!std::getline(in, line)) return table;
  {
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) table.names.push_back(cell);
  }
  table.columns.resize(table.names.size());
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.empty()) continue;
    std::vector<double> values;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) {
      try {
        values.push_back(std::stod(cell));
      } catch (const std::exception&) {
        values.push_back(NAN);
      }
    }
    if (values.size() != table.names.size()) break;  // a row cut by a crash: the rows before it
    for (std::size_t i = 0; i < values.size(); ++i) table.columns[i].push_back(values[i]);
  }
  return table;
}

}  // namespace fsi
