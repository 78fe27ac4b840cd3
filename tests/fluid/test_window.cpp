// Waveform iterations with the Navier-Stokes fluid (fluid.substeps > 1,
// NavierStokesFluid::solve_window): a window of n substeps equals n successive solve_step +
// accept_step calls fed the same interpolated interface data (to round-off), a repeated call
// (the next coupling iteration) restarts from the window's start whatever the call before it
// was given, and the window's end is the state accept_step() accepts: the probes after a window
// equal those after its last substep. On a moving cylinder (tests/fluid/prescribed_motion.hpp's
// mesh), BDF2 (parabolic interpolation) and BDF1 (linear), fixed and incremental mesh motion.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/waveform.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"

namespace {

using fsi::fluid::NavierStokesFluid;

constexpr double kWindow = 0.02;  // the coupling window Dt

struct Case {
  std::string element = "p1p1";
  std::string scheme = "bdf2";
  bool incremental = false;
  bool reuse = false;  // reuse_factorisation (BiCGSTAB on old factors: equal to its tolerance only)
};

std::string scene_text(const Case& c) {
  return std::string(R"(
fluid:
  model: fem
  element: )") +
         c.element + R"(
  mesh: {geo: )" +
         FSI_FLUID_SOURCE_DIR + R"(/configs/meshes/dfg_cylinder.geo, size: 0.1, parameters: {hc: 0.025}}
  density: 1.0
  viscosity: 0.001
  scheme: )" + c.scheme +
         R"(
  nonlinear: {max_iterations: 2, tolerance: 1.0e-12}
  linear_solver: {reuse_factorisation: )" +
         (c.reuse ? "true" : "false") + R"(}
  inflow: [{group: inlet, max_velocity: 1.5, ramp_time: 0.05}]
  walls: [walls]
  outlet: [outlet]
  interface: {groups: [cylinder], penalty: 50.0, symmetry: -1, mesh_incremental: )" +
         (c.incremental ? "true" : "false") + R"(}
  forces: [{name: cyl, groups: [cylinder]}]
  pressure_probes: {p_front: [0.15, 0.2]}
)";
}

struct Model {
  explicit Model(const Case& c) : scene(fsi::Scene::parse(scene_text(c), "inline")) {
    fsi::FluidSetup setup;
    setup.dt = kWindow;
    setup.end_time = 1.0;
    model.configure(scene.section("fluid"), setup);
    nodes = static_cast<Eigen::Index>(model.interface().nodes());
  }
  fsi::Scene scene;
  NavierStokesFluid model;
  Eigen::Index nodes = 0;
};

// The cylinder's motion at time t (every interface node alike), scaled by `factor` (a
// coupling iteration's wrong guess: factor != 1).
void motion(Eigen::Index nodes, double t, double factor, Eigen::VectorXd& d, Eigen::VectorXd& v) {
  const double w = 2 * M_PI / 0.16, a = 0.004 * factor;
  d.resize(2 * nodes);
  v.resize(2 * nodes);
  for (Eigen::Index i = 0; i < nodes; ++i) {
    d(2 * i) = 0.3 * a * std::sin(0.5 * w * t);
    d(2 * i + 1) = a * std::sin(w * t);
    v(2 * i) = 0.3 * a * 0.5 * w * std::cos(0.5 * w * t);
    v(2 * i + 1) = a * w * std::cos(w * t);
  }
}

// The interface waveforms over window `n` as the coupler sends them: the window's start, then
// `samples` samples (a solid in that many substeps); the fluid interpolates between them.
void waveforms(Eigen::Index nodes, int n, int samples, double factor, fsi::Waveform& d, fsi::Waveform& v) {
  d = v = fsi::Waveform{};
  const double start = (n - 1) * kWindow;
  for (int j = 0; j <= samples; ++j) {
    const double t = j == 0 ? start : fsi::substep_time(start, kWindow, j, samples);
    Eigen::VectorXd dj, vj;
    motion(nodes, t, j == 0 ? 1.0 : factor, dj, vj);
    d.times.push_back(t), v.times.push_back(t);
    d.values.push_back(dj), v.values.push_back(vj);
  }
}

double max_difference(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  EXPECT_EQ(a.size(), b.size());
  return a.size() == b.size() && a.size() > 0 ? (a - b).cwiseAbs().maxCoeff() : INFINITY;
}

class FluidWindow : public ::testing::TestWithParam<std::tuple<std::string, std::string, bool>> {};

TEST_P(FluidWindow, EqualsSuccessiveSubstepsAndRestartsFromTheWindowStart) {
  Case c;
  c.element = std::get<0>(GetParam());
  c.scheme = std::get<1>(GetParam());
  c.incremental = std::get<2>(GetParam());
  const int substeps = 4, samples = 2, windows = 3;
  Model a(c), b(c);
  ASSERT_TRUE(a.model.supports_substeps());
  const Eigen::Index m = 2 * a.nodes;
  std::map<std::string, double> probes_a, probes_b;
  for (int n = 1; n <= windows; ++n) {
    SCOPED_TRACE("window " + std::to_string(n));
    const fsi::StepInfo info{n * kWindow, kWindow, n, 1};
    fsi::Waveform d, v, wrong_d, wrong_v;
    waveforms(a.nodes, n, samples, 1.0, d, v);
    waveforms(a.nodes, n, samples, 1.3, wrong_d, wrong_v);
    // Coupling iteration 1 with a wrong guess, 2 and 3 with the right one: 2 restarts from the
    // window's start (not from 1's end), and 3 repeats 2.
    a.model.solve_window(info, wrong_d, wrong_v, substeps);
    const fsi::FluidLoads second = a.model.solve_window({n * kWindow, kWindow, n, 2}, d, v, substeps);
    const fsi::FluidLoads third = a.model.solve_window({n * kWindow, kWindow, n, 3}, d, v, substeps);
    ASSERT_EQ(second.traction_samples.size(), m * substeps);
    ASSERT_EQ(second.velocity_integral_samples.size(), m * substeps);
    const double scale = second.traction_samples.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 0);
    EXPECT_LE(max_difference(second.traction_samples, third.traction_samples), 1e-12 * scale);
    // The window's end is also the loads' own traction_force / velocity_integral.
    EXPECT_EQ(max_difference(second.traction_samples.tail(m), second.traction_force), 0.0);
    EXPECT_EQ(max_difference(second.velocity_integral_samples.tail(m), second.velocity_integral), 0.0);
    probes_a = a.model.accept_step({n * kWindow, kWindow, n, 3});

    // The same substeps one by one, with the data interpolated as the window does.
    d.degree = v.degree = c.scheme == "bdf1" ? 1 : 2;
    for (int j = 1; j <= substeps; ++j) {
      SCOPED_TRACE("substep " + std::to_string(j));
      const double t = fsi::substep_time((n - 1) * kWindow, kWindow, j, substeps);
      const fsi::StepInfo sub{t, kWindow / substeps, (n - 1) * substeps + j, 1};
      const fsi::FluidLoads one = b.model.solve_step(sub, d.at(t), v.at(t));
      EXPECT_LE(max_difference(one.traction_force, third.traction_samples.segment((j - 1) * m, m)), 1e-11 * scale);
      EXPECT_LE(max_difference(one.velocity_integral, third.velocity_integral_samples.segment((j - 1) * m, m)),
                1e-11 * third.velocity_integral_samples.cwiseAbs().maxCoeff());
      probes_b = b.model.accept_step(sub);
    }
  }
  // The accepted window ends agree: the probes after the last window and after its last substep.
  for (const char* name : {"cyl_drag", "cyl_lift", "p_front", "mesh_min_scaled_jacobian"}) {
    ASSERT_EQ(probes_a.count(name), 1u) << name;
    EXPECT_NEAR(probes_a.at(name), probes_b.at(name), 1e-10 * std::max(1.0, std::abs(probes_b.at(name)))) << name;
  }
  EXPECT_GT(std::abs(probes_a.at("cyl_drag")), 1e-4);  // the flow did move
  // The wrong first iterations were solved too: more factorisations than the one-by-one run.
  EXPECT_GT(probes_a.at("factorisations"), probes_b.at("factorisations"));
}

INSTANTIATE_TEST_SUITE_P(ElementsSchemesMeshMotion, FluidWindow,
                         ::testing::Values(std::make_tuple(std::string("p1p1"), std::string("bdf2"), false),
                                           std::make_tuple(std::string("p1p1"), std::string("bdf1"), true),
                                           std::make_tuple(std::string("p2p1"), std::string("bdf2"), true)),
                         [](const auto& info) {
                           return std::get<0>(info.param) + "_" + std::get<1>(info.param) +
                                  (std::get<2>(info.param) ? "_incremental" : "_fixed_operator");
                         });

// With the factors reused (BiCGSTAB preconditioned by older factors, the default) the window's
// substeps see other factors than the one-by-one run: equal to the Krylov tolerance.
TEST(FluidWindow, WithReusedFactorsEqualsSuccessiveSubstepsToTheKrylovTolerance) {
  Case c;
  c.reuse = true;
  c.incremental = true;
  Model a(c), b(c);
  const int substeps = 2;
  const Eigen::Index m = 2 * a.nodes;
  for (int n = 1; n <= 3; ++n) {
    fsi::Waveform d, v, wrong_d, wrong_v;
    waveforms(a.nodes, n, 1, 1.0, d, v);
    waveforms(a.nodes, n, 1, 0.7, wrong_d, wrong_v);
    a.model.solve_window({n * kWindow, kWindow, n, 1}, wrong_d, wrong_v, substeps);
    const auto loads = a.model.solve_window({n * kWindow, kWindow, n, 2}, d, v, substeps);
    a.model.accept_step({n * kWindow, kWindow, n, 2});
    const double scale = loads.traction_samples.cwiseAbs().maxCoeff();
    for (int j = 1; j <= substeps; ++j) {
      const double t = fsi::substep_time((n - 1) * kWindow, kWindow, j, substeps);
      const fsi::StepInfo sub{t, kWindow / substeps, (n - 1) * substeps + j, 1};
      const auto one = b.model.solve_step(sub, d.at(t), v.at(t));
      EXPECT_LE(max_difference(one.traction_force, loads.traction_samples.segment((j - 1) * m, m)), 1e-7 * scale)
          << "window " << n << " substep " << j;
      b.model.accept_step(sub);
    }
  }
}

TEST(FluidWindow, SteadyFluidTakesNoSubsteps) {
  Case c;
  c.scheme = "steady";
  Model a(c);
  EXPECT_FALSE(a.model.supports_substeps());
  Model b(Case{});
  EXPECT_TRUE(b.model.supports_substeps());
}

}  // namespace
