#pragma once
// Waveform iterations with subcycling (a coupling window Dt = time.dt, each solver in
// `substeps` steps of Dt / substeps): the interface data a solver exchanges over a window as
// samples in time, and the time interpolation a receiving solver evaluates at its own
// substep times. Pure data: no sockets, no protobuf.
#include <Eigen/Core>
#include <vector>

#include "fsi/common/scene_schema.hpp"

namespace fsi {

// Samples of an interface vector over a coupling window: values[i] at times[i], increasing,
// from the window's start (the accepted value; a solid may also get the previous window's end
// before it) to its end. at(t) interpolates piecewise linearly between the two samples around
// t; with degree 2 (a second-order solver) by the parabola through the three samples nearest to
// t (the previous window's end among them near the window's start, when it is there).
struct Waveform {
  std::vector<double> times;
  std::vector<Eigen::VectorXd> values;
  int degree = 1;
  // The sample itself at a sample's time (to round-off of the window's length); interpolated
  // between samples; the first / last sample outside the window.
  Eigen::VectorXd at(double t) const;
  // The window [start, start + dt] of `count` samples after the start value: times
  // start + j dt / count, values the blocks of `samples` (count blocks of start_value.size()).
  static Waveform window(double start, double dt, const Eigen::VectorXd& start_value, const Eigen::VectorXd& samples,
                         int count);
};

// The end time of substep j (1-based) of `count` in the window [start, start + dt].
inline double substep_time(double start, double dt, int j, int count) {
  return j == count ? start + dt : start + dt * j / count;
}

// The key every solver section takes: `substeps` (declared in common/src/window_keys.cpp; the
// coupler reads it, the solver is told in each solve request).
std::vector<schema::Key> window_keys();
// A solver section's `substeps` (the coupler's and a server's reader: it marks the key used).
int substeps_of(const ConfigSection& section);

}  // namespace fsi
