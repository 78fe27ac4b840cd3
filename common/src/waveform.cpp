#include "fsi/common/waveform.hpp"

#include <cmath>
#include <stdexcept>

#include "fsi/common/scene_reader.hpp"

namespace fsi {

Eigen::VectorXd Waveform::at(double t) const {
  if (values.empty() || values.size() != times.size()) throw std::logic_error("waveform: no samples");
  const std::size_t n = times.size();
  const double span = std::max(times.back() - times.front(), 1e-300);
  for (std::size_t i = 0; i < n; ++i)
    if (std::abs(t - times[i]) <= 1e-10 * span) return values[i];
  if (t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  std::size_t i = 1;
  while (times[i] < t) ++i;  // times[i - 1] < t < times[i]
  if (degree >= 2 && n >= 3) {
    // Lagrange through three neighbouring samples: i - 1, i and the nearer other neighbour.
    std::size_t a = i - 1;
    if (a > 0 && (i + 1 >= n || t - times[a - 1] < times[i + 1] - t)) --a;
    if (a + 2 >= n) a = n - 3;
    Eigen::VectorXd out = Eigen::VectorXd::Zero(values[a].size());
    for (std::size_t p = a; p < a + 3; ++p) {
      double w = 1;
      for (std::size_t q = a; q < a + 3; ++q)
        if (q != p) w *= (t - times[q]) / (times[p] - times[q]);
      out += w * values[p];
    }
    return out;
  }
  const double s = (t - times[i - 1]) / (times[i] - times[i - 1]);
  return (1 - s) * values[i - 1] + s * values[i];
}

Waveform Waveform::window(double start, double dt, const Eigen::VectorXd& start_value, const Eigen::VectorXd& samples,
                          int count) {
  const Eigen::Index m = start_value.size();
  if (samples.size() != m * count) throw std::invalid_argument("waveform: samples are not count blocks of the start");
  Waveform w;
  w.times.push_back(start);
  w.values.push_back(start_value);
  for (int j = 1; j <= count; ++j) {
    w.times.push_back(substep_time(start, dt, j, count));
    w.values.push_back(samples.segment((j - 1) * m, m));
  }
  return w;
}

int substeps_of(const ConfigSection& section) {
  static const std::vector<schema::Key> keys = window_keys();
  return schema::Reader(section, keys).get<int>("substeps");
}

}  // namespace fsi
