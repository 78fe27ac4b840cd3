// Checkpoints of the fluid, restored bit for bit: a model saved after step k (state
// serialised to bytes and parsed back) and a fresh model loading that state continue with
// identical probes and interface loads (==, not approximately), for both elements, with and
// without factor reuse, on a moving mesh with two coupling iterations per step. Also: two
// uninterrupted runs are identical (no timing-dependent linear-solver decisions), a state of
// another mesh or element is refused naming the entry, and the surrogate fluid round-trips.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/state.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"
#include "fsi/models/surrogate_fluid.hpp"
#include "prescribed_motion.hpp"

namespace {

using fsi::fluid::NavierStokesFluid;

struct Case {
  std::string element = "p1p1";
  bool reuse = true;
  bool incremental = false;  // incremental mesh motion (the operator is rebuilt after each step)
  bool relinearise = false;  // coupling iterations linearise about the last iterate
  double size = 0.08;
};

std::string scene_text(const Case& c) {
  return std::string(R"(
fluid:
  model: fem
  element: )") +
         c.element + R"(
  mesh: {geo: )" +
         FSI_FLUID_SOURCE_DIR + "/configs/meshes/dfg_cylinder.geo, size: " + std::to_string(c.size) +
         R"(, parameters: {hc: 0.02}}
  density: 1.0
  viscosity: 0.001
  scheme: bdf2
  nonlinear: {max_iterations: 1, relinearise: )" +
         (c.relinearise ? "true" : "false") + R"(}
  linear_solver: {reuse_factorisation: )" +
         (c.reuse ? "true" : "false") + R"(}
  inflow: [{group: inlet, max_velocity: 1.5, ramp_time: 0.05}]
  walls: [walls]
  outlet: [outlet]
  interface: {groups: [cylinder], penalty: 50.0, symmetry: -1, mesh_incremental: )" +
         (c.incremental ? "true" : "false") + R"(}
  forces: [{name: cyl, groups: [cylinder], reference_velocity: 1.0, reference_length: 0.1}]
  pressure_probes: {p_front: [0.15, 0.2], p_back: [0.25, 0.2]}
  pressure_differences: {dp: [p_front, p_back]}
)";
}

using namespace fluid_test;

struct Model {
  explicit Model(const Case& c) : scene(fsi::Scene::parse(scene_text(c), "inline")) {
    fsi::FluidSetup setup;
    setup.dt = kDt;
    setup.end_time = 1.0;
    model.configure(scene.section("fluid"), setup);
    nodes = static_cast<Eigen::Index>(model.interface().nodes());
  }
  fsi::Scene scene;
  NavierStokesFluid model;
  Eigen::Index nodes = 0;
};

class FluidCheckpoint : public ::testing::TestWithParam<std::tuple<std::string, bool, bool>> {};

TEST_P(FluidCheckpoint, RestoredModelContinuesBitForBit) {
  Case c;
  c.element = std::get<0>(GetParam());
  c.reuse = std::get<1>(GetParam());
  c.incremental = c.relinearise = std::get<2>(GetParam());
  const int k = 5, n = 12;

  Model a(c);
  ASSERT_TRUE(a.model.supports_checkpoint());
  std::string bytes;
  std::vector<StepRecord> expected;
  for (int step = 1; step <= n; ++step) {
    const auto r = run_step(a.model, a.nodes, step);
    if (step == k) {
      fsi::StateArchive state;
      a.model.save_state(state);
      bytes = state.serialize();
    }
    if (step > k) expected.push_back(r);
  }
  ASSERT_FALSE(bytes.empty());
  const auto state = fsi::StateArchive::parse(bytes, "fluid checkpoint of step 5");
  for (const char* entry : {"flow.u", "flow.u_n", "flow.u_nm1", "flow.x", "flow.x_n", "flow.x_nm1", "flow.dt_n",
                            "flow.accepted_steps", "flow.lu.ordering", "mesh.base_displacement", "mesh.base_moving",
                            "fluid.last_interface_displacement", "fluid.factorisations"})
    EXPECT_TRUE(state.has(entry)) << entry;
  EXPECT_EQ(state.integer("flow.accepted_steps"), k);
  EXPECT_NE(state.text("flow.lu.ordering"), "auto");  // chosen at the first factorisation

  Model b(c);
  b.model.load_state(state);
  for (int step = k + 1; step <= n; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    const auto r = run_step(b.model, b.nodes, step);
    expect_identical(expected[static_cast<std::size_t>(step - k - 1)], r, step);
    if (HasFatalFailure()) return;
  }
  // The flow did move (the comparison is not between two zero states).
  EXPECT_GT(std::abs(expected.back().probes.at("cyl_drag")), 1e-4);
  const double factorisations_after =
      expected.back().probes.at("factorisations") - state.integer("fluid.factorisations");
  if (c.reuse)
    EXPECT_LT(factorisations_after, 2 * (n - k)) << "BiCGSTAB on old factors was not exercised";
  else
    EXPECT_EQ(factorisations_after, 2 * (n - k));
}

INSTANTIATE_TEST_SUITE_P(ElementsReuseAndMeshMotion, FluidCheckpoint,
                         ::testing::Combine(::testing::Values(std::string("p1p1"), std::string("p2p1")),
                                            ::testing::Bool(), ::testing::Bool()),
                         [](const auto& info) {
                           return std::get<0>(info.param) + (std::get<1>(info.param) ? "_reuse" : "_direct") +
                                  (std::get<2>(info.param) ? "_incremental_relinearised" : "_fixed_operator");
                         });

TEST(FluidCheckpoint, TwoUninterruptedRunsAreIdentical) {
  // No wall-clock timing decides the ordering or when to refactorise.
  Case c;
  Model a(c), b(c);
  for (int step = 1; step <= 8; ++step) {
    const auto ra = run_step(a.model, a.nodes, step);
    const auto rb = run_step(b.model, b.nodes, step);
    expect_identical(ra, rb, step);
    if (HasFatalFailure()) return;
  }
}

TEST(FluidCheckpoint, StateOfAnotherMeshIsRefusedNamingTheEntry) {
  Case coarse;
  coarse.size = 0.1;
  Model a(coarse);
  run_step(a.model, a.nodes, 1);
  fsi::StateArchive saved;
  a.model.save_state(saved);
  const auto state = fsi::StateArchive::parse(saved.serialize(), "fluid checkpoint of step 1");

  Model b(Case{});  // size 0.08
  ASSERT_NE(b.model.solver().dofs(), a.model.solver().dofs());
  try {
    b.model.load_state(state);
    FAIL() << "expected fsi::StateError";
  } catch (const fsi::StateError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("entry '"), std::string::npos) << what;
    EXPECT_NE(what.find("needs"), std::string::npos) << what;
  }

  Case p2 = coarse;
  p2.element = "p2p1";
  Model c(p2);
  try {
    c.model.load_state(state);
    FAIL() << "expected fsi::StateError";
  } catch (const fsi::StateError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'flow.element'"), std::string::npos) << what;
  }
}

TEST(SurrogateFluidCheckpoint, RestoredModelContinuesBitForBit) {
  const std::string text =
      "fluid: {model: surrogate, force: [1.282, -0.25], added_mass: 0.37, interface_measure: 2.5}\n";
  auto make = [&](fsi::Scene& scene, fsi::models::SurrogateFluid& m) {
    fsi::FluidSetup setup;
    setup.dt = 0.1;
    m.configure(scene.section("fluid"), setup);
    (void)m.interface();
  };
  auto input = [](int step, int iteration) {
    Eigen::VectorXd v(2);
    v << std::sin(0.7 * step) + 0.01 * iteration, std::cos(1.3 * step) / 3;
    return v;
  };
  auto scene_a = fsi::Scene::parse(text, "inline");
  fsi::models::SurrogateFluid a;
  make(scene_a, a);
  EXPECT_TRUE(a.supports_checkpoint());
  a.initial_loads(Eigen::VectorXd::Zero(2), input(0, 0));
  std::string bytes;
  std::vector<std::pair<fsi::FluidLoads, std::map<std::string, double>>> expected;
  const int k = 3, n = 7;
  for (int step = 1; step <= n; ++step) {
    fsi::FluidLoads loads;
    for (int it = 1; it <= 2; ++it)
      loads = a.solve_step(fsi::StepInfo{0.1 * step, 0.1, step, it}, Eigen::VectorXd::Zero(2), input(step, it));
    const auto probes = a.accept_step(fsi::StepInfo{0.1 * step, 0.1, step, 2});
    if (step == k) {
      fsi::StateArchive s;
      a.save_state(s);
      bytes = s.serialize();
    }
    if (step > k) expected.emplace_back(loads, probes);
  }
  auto scene_b = fsi::Scene::parse(text, "inline");
  fsi::models::SurrogateFluid b;
  make(scene_b, b);
  b.load_state(fsi::StateArchive::parse(bytes, "surrogate checkpoint"));
  for (int step = k + 1; step <= n; ++step) {
    fsi::FluidLoads loads;
    for (int it = 1; it <= 2; ++it)
      loads = b.solve_step(fsi::StepInfo{0.1 * step, 0.1, step, it}, Eigen::VectorXd::Zero(2), input(step, it));
    const auto probes = b.accept_step(fsi::StepInfo{0.1 * step, 0.1, step, 2});
    const auto& [eloads, eprobes] = expected[static_cast<std::size_t>(step - k - 1)];
    expect_identical(eloads.traction_force, loads.traction_force, "traction");
    expect_identical(eloads.velocity_integral, loads.velocity_integral, "velocity integral");
    EXPECT_EQ(eprobes, probes);
  }
  fsi::StateArchive wrong;
  wrong.put("surrogate.v_n", Eigen::VectorXd::Zero(3));
  EXPECT_THROW(b.load_state(wrong), fsi::StateError);
}

}  // namespace
