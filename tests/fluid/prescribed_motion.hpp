#pragma once
// The fluid tests' prescribed interface motion and bit-for-bit comparisons (test_checkpoint.cpp,
// test_remesh.cpp): a step of two coupling iterations with a prescribed cylinder motion, its
// tractions, velocity integrals and probes, compared bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "fsi/fluid/navier_stokes_fluid.hpp"

namespace fluid_test {

constexpr double kDt = 0.01;

// The prescribed interface motion: the cylinder oscillates across the channel and a little
// along it; coupling iteration 1 gets a perturbed (predicted) state, iteration 2 the exact one.
inline void interface_state(Eigen::Index nodes, int step, int iteration, Eigen::VectorXd& d, Eigen::VectorXd& v) {
  const double t = step * kDt, w = 2 * M_PI / 0.16, a = 0.004;
  const double perturbation = iteration == 1 ? 1.05 : 1.0;
  d.resize(2 * nodes);
  v.resize(2 * nodes);
  for (Eigen::Index i = 0; i < nodes; ++i) {
    d(2 * i) = 0.3 * a * std::sin(0.5 * w * t) * perturbation;
    d(2 * i + 1) = a * std::sin(w * t) * perturbation;
    v(2 * i) = 0.3 * a * 0.5 * w * std::cos(0.5 * w * t) * perturbation;
    v(2 * i + 1) = a * w * std::cos(w * t) * perturbation;
  }
}

struct StepRecord {
  std::vector<Eigen::VectorXd> traction, velocity_integral;  // per coupling iteration
  std::map<std::string, double> probes;
};

inline StepRecord run_step(fsi::fluid::NavierStokesFluid& model, Eigen::Index nodes, int step) {
  StepRecord r;
  for (int k = 1; k <= 2; ++k) {
    Eigen::VectorXd d, v;
    interface_state(nodes, step, k, d, v);
    const auto loads = model.solve_step(fsi::StepInfo{step * kDt, kDt, step, k}, d, v);
    r.traction.push_back(loads.traction_force);
    r.velocity_integral.push_back(loads.velocity_integral);
  }
  r.probes = model.accept_step(fsi::StepInfo{step * kDt, kDt, step, 2});
  return r;
}

inline std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

inline void expect_identical(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  ASSERT_GT(a.size(), 0) << what;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    ASSERT_EQ(bits(a(i)), bits(b(i))) << what << " entry " << i << ": " << a(i) << " vs " << b(i) << " (difference "
                                      << a(i) - b(i) << ")";
}

inline void expect_identical(const StepRecord& a, const StepRecord& b, int step) {
  const std::string at = "step " + std::to_string(step);
  ASSERT_EQ(a.traction.size(), b.traction.size());
  for (std::size_t k = 0; k < a.traction.size(); ++k) {
    expect_identical(a.traction[k], b.traction[k], at + " iteration " + std::to_string(k + 1) + " traction");
    expect_identical(a.velocity_integral[k], b.velocity_integral[k],
                     at + " iteration " + std::to_string(k + 1) + " velocity integral");
  }
  ASSERT_EQ(a.probes.size(), b.probes.size()) << at;
  for (const auto& [name, value] : a.probes) {
    ASSERT_EQ(b.probes.count(name), 1u) << at << " probe " << name;
    EXPECT_EQ(bits(value), bits(b.probes.at(name)))
        << at << " probe " << name << ": " << value << " vs " << b.probes.at(name);
  }
}

}  // namespace fluid_test
