// Solid benchmarks outside the test suite.
//
// Sample runs (from the repository root, after building the target solid_bench):
//   build/bin/solid_bench run configs/csm1.yaml                      # static: final A_x, A_y
//   build/bin/solid_bench run configs/csm3.yaml                      # dynamic: mean/amplitude/frequency
//   build/bin/solid_bench run configs/csm3.yaml solid.time_scheme=bdf1
//   build/bin/solid_bench timing [cholmod|umfpack]                   # Newton iteration / step timings
//   build/bin/solid_bench phases configs/cantilever_strip_3d.yaml "solid.mesh.divisions=[64, 8, 32]"
//       # one Newton iteration by phases (assembly, factorisation, solve), peak memory: JSON
// Extra arguments key=value override scene keys (as the solid_server's --set).
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/resource.h>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/version.hpp"
#include "fsi/solid/fem_solid.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Oscillation {
  double mean = 0, amplitude = 0, frequency = 0;
};

// Turek-Hron style: over the last full period, mean = (max + min)/2, amplitude =
// (max - min)/2; the period between the last two upward crossings of the mean (linear
// interpolation, with hysteresis so that high-frequency ripple is not counted).
Oscillation analyse(const std::vector<double>& t, const std::vector<double>& y) {
  Oscillation o;
  if (t.size() < 4) return o;
  // Mean level from the second half of the record.
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = t.size() / 2; i < t.size(); ++i) lo = std::min(lo, y[i]), hi = std::max(hi, y[i]);
  const double level = 0.5 * (hi + lo), band = 0.1 * (hi - lo);
  std::vector<double> crossings;
  bool below = false;
  for (std::size_t i = 1; i < y.size(); ++i) {
    if (y[i] < level - band) below = true;
    if (below && y[i - 1] < level && y[i] >= level) {
      crossings.push_back(t[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]));
      below = false;
    }
  }
  if (crossings.size() < 2) return o;
  const double t0 = crossings[crossings.size() - 2], t1 = crossings.back();
  o.frequency = 1.0 / (t1 - t0);
  lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] >= t0 && t[i] <= t1) lo = std::min(lo, y[i]), hi = std::max(hi, y[i]);
  o.mean = 0.5 * (hi + lo);
  o.amplitude = 0.5 * (hi - lo);
  return o;
}

int run(const std::string& scene_file, const std::vector<std::string>& overrides) {
  auto scene = fsi::Scene::load(scene_file, overrides);
  auto time = scene.section("time");
  const double dt = time.get<double>("dt"), end = time.get<double>("end");
  auto section = scene.section("solid");
  section.get<std::string>("model");
  fsi::SolidSetup setup;
  setup.dt = dt;
  setup.end_time = end;
  fsi::solid::FemSolid solid;
  const auto t_start = Clock::now();
  solid.configure(section, setup);
  scene.check_all_used("solid");
  const auto iface = solid.interface();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(iface.nodes()));
  std::vector<double> ts, ax, ay;
  std::map<std::string, double> probes;
  const int steps = static_cast<int>(std::lround(end / dt));
  long newton = 0;
  for (int n = 1; n <= steps; ++n) {
    fsi::StepInfo info{n * dt, dt, n, 0};
    newton += solid.solve_step(info, zero).newton_iterations;
    probes = solid.accept_step(info);
    ts.push_back(info.time);
    ax.push_back(probes["A_x"]);
    ay.push_back(probes["A_y"]);
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t_start).count();
  fmt::print("scene {} ({} steps, {} Newton iterations, {:.2f} s, {} free dofs)\n", scene_file, steps, newton, seconds,
             solid.system().num_free());
  if (steps == 1 || solid.scheme() == fsi::solid::TimeScheme::Static) {
    fmt::print("A_x = {:.6e}  A_y = {:.6e}\n", ax.back(), ay.back());
    return 0;
  }
  if (const char* csv = std::getenv("SOLID_BENCH_CSV")) {
    std::ofstream out(csv);
    out << "time,A_x,A_y\n";
    for (std::size_t i = 0; i < ts.size(); ++i) out << fmt::format("{:.6f},{:.9e},{:.9e}\n", ts[i], ax[i], ay[i]);
  }
  const auto ox = analyse(ts, ax), oy = analyse(ts, ay);
  fmt::print("A_x: mean {:.4f}e-3 amplitude {:.4f}e-3 frequency {:.4f} Hz\n", ox.mean * 1e3, ox.amplitude * 1e3,
             ox.frequency);
  fmt::print("A_y: mean {:.4f}e-3 amplitude {:.4f}e-3 frequency {:.4f} Hz\n", oy.mean * 1e3, oy.amplitude * 1e3,
             oy.frequency);
  return 0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Median timings of one Newton iteration (assembly + factorisation + solve) and of one
// dynamic step on the paper's beam meshes.
int timing(const std::string& linear_solver) {
  struct Case {
    const char* name;
    int nx, ny;
  };
  for (const Case c : {Case{"4x100", 4, 100}, Case{"10x30", 10, 30}}) {
    const std::string text = fmt::format(R"(
time: {{dt: 0.01, end: 1}}
solid:
  mesh: {{type: rectangle, origin: [0, 0], size: [0.05, 0.3], elements: [{}, {}]}}
  material: {{law: neo_hookean, youngs_modulus: 200.0, poisson_ratio: 0.3}}
  density: 1.0
  gravity: [1.0, 0.0]
  analysis: dynamic
  time_scheme: bdf1
  clamp: bottom
  interface: [left, top, right]
  linear_solver: {}
)",
                                         c.nx, c.ny, linear_solver);
    auto scene = fsi::Scene::parse(text, "timing");
    fsi::SolidSetup setup{0.01, 1.0, 0.0, {}};
    fsi::solid::FemSolid solid;
    solid.configure(scene.section("solid"), setup);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(solid.interface().nodes()));
    std::vector<double> step_ms, iter_ms, assemble_ms, factor_ms;
    int iterations = 0;
    for (int n = 1; n <= 40; ++n) {
      fsi::StepInfo info{n * 0.01, 0.01, n, 0};
      const auto t0 = Clock::now();
      iterations += solid.solve_step(info, zero).newton_iterations;
      step_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
      solid.accept_step(info);
      // One Newton iteration on the current state, timed by parts.
      auto& sys = solid.system();
      fsi::solid::SparseMatrix K;
      Eigen::VectorXd r;
      const auto a0 = Clock::now();
      sys.assemble(solid.displacement(), Eigen::VectorXd::Zero(sys.num_dofs()), fsi::solid::TimeTerms{1e4, 1e2, {}, {}},
                   K, r);
      const auto a1 = Clock::now();
      sys.linear_solver().factorize(K);
      const Eigen::VectorXd x = sys.linear_solver().solve(r);
      const auto a2 = Clock::now();
      assemble_ms.push_back(std::chrono::duration<double, std::milli>(a1 - a0).count());
      factor_ms.push_back(std::chrono::duration<double, std::milli>(a2 - a1).count());
      iter_ms.push_back(std::chrono::duration<double, std::milli>(a2 - a0).count());
    }
    fmt::print(
        "[{}] mesh {} ({} free dofs): Newton iteration {:.3f} ms (assembly {:.3f} + factorise/solve {:.3f}), "
        "step {:.3f} ms ({:.1f} iterations/step), medians of 40\n",
        linear_solver, c.name, solid.system().num_free(), median(iter_ms), median(assemble_ms), median(factor_ms),
        median(step_ms), iterations / 40.0);
  }
  return 0;
}

// One Newton iteration of a scene's solid at rest, by phases, `repeats` times: the assembly
// of the tangent and residual, the factorisation (CHOLMOD's symbolic analysis is in the
// first one only: reported apart), the solve; the peak resident memory of the process. One
// JSON line (bench/solid/phases_3d.py reads it).
int phases(const std::string& scene_file, const std::vector<std::string>& overrides, int repeats = 4) {
  auto scene = fsi::Scene::load(scene_file, overrides);
  auto time = scene.section("time");
  fsi::SolidSetup setup;
  setup.dt = time.get<double>("dt");
  setup.end_time = time.get<double>("end");
  fsi::solid::FemSolid solid;
  auto t = Clock::now();
  auto lap = [&t] {
    const auto now = Clock::now();
    const double s = std::chrono::duration<double>(now - t).count();
    t = now;
    return s;
  };
  solid.configure(scene.section("solid"), setup);
  const double setup_s = lap();
  auto& sys = solid.system();
  const Eigen::VectorXd d = Eigen::VectorXd::Zero(sys.num_dofs()), f = Eigen::VectorXd::Ones(sys.num_dofs());
  fsi::solid::SparseMatrix K;
  Eigen::VectorXd r;
  std::vector<double> assembly, factorisation, solve;
  double check = 0;
  for (int k = 0; k < repeats; ++k) {
    lap();
    sys.assemble(d, f, fsi::solid::TimeTerms{}, K, r);
    assembly.push_back(lap());
    sys.linear_solver().factorize(K);
    factorisation.push_back(lap());
    const Eigen::VectorXd x = sys.linear_solver().solve(r);
    solve.push_back(lap());
    check = (K * x - r).norm() / r.norm();
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto list = [](const std::vector<double>& v) { return fmt::format("{:.6f}", fmt::join(v, ", ")); };
  fmt::print(
      "{{\"solver\": \"solid_server\", \"free_dofs\": {}, \"nonzeros\": {}, \"setup\": {:.6f}, \"assembly\": [{}], "
      "\"factorisation\": [{}], \"solve\": [{}], \"relative_residual\": {:.3e}, \"peak_rss_mb\": {:.1f}}}\n",
      sys.num_free(), K.nonZeros(), setup_s, list(assembly), list(factorisation), list(solve), check,
      usage.ru_maxrss / 1024.0);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "--version") {
      std::printf("%s\n", fsi::version_line("solid_bench").c_str());
      return 0;
    }
    if (mode == "run" && argc > 2) return run(argv[2], std::vector<std::string>(argv + 3, argv + argc));
    if (mode == "timing") return timing(argc > 2 ? argv[2] : "cholmod");
    if (mode == "phases" && argc > 2) return phases(argv[2], std::vector<std::string>(argv + 3, argv + argc));
    std::fprintf(stderr,
                 "usage: solid_bench run SCENE [key=value ...] | solid_bench timing [cholmod|umfpack] | "
                 "solid_bench phases SCENE [key=value ...]\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
