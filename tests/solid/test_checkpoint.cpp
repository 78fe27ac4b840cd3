// FemSolid checkpoints: a model restored from a saved state continues bit for bit like the
// one that was never interrupted, for every time scheme, with and without the Algorithm 2
// interface damping; a state of another mesh or scheme is refused naming the entry.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <tuple>

#include "fsi/solid/fem_solid.hpp"

namespace {

std::string beam_scene(const std::string& analysis, const std::string& scheme, int elements = 20) {
  return R"(
solid:
  model: fem
  mesh: {type: rectangle, origin: [0, 0], size: [1.0, 0.1], elements: [)" +
         std::to_string(elements) + R"(, 2]}
  material: {law: neo_hookean, youngs_modulus: 1.0e4, poisson_ratio: 0.3}
  density: 10.0
  analysis: )" +
         analysis + R"(
  time_scheme: )" +
         scheme + R"(
  clamp: left
  interface: [top, right, bottom]
  probes: [{name: tip, point: [1.0, 0.05]}]
)";
}

std::unique_ptr<fsi::solid::FemSolid> make(const fsi::Scene& scene, double dt, double damping) {
  auto solid = std::make_unique<fsi::solid::FemSolid>();
  auto section = scene.section("solid");
  section.get<std::string>("model");
  solid->configure(section, fsi::SolidSetup{dt, 1.0, damping, {}});
  return solid;
}

// A force history on the interface: a pull on the tip that varies in time, and two coupling
// iterations per step (the first with a perturbed force), as the coupler would send.
Eigen::VectorXd force(const fsi::InterfaceMeshData& itf, int step, int iteration) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(itf.nodes()));
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(itf.nodes()); ++i)
    if (itf.coordinates(i, 0) > 0.99) f[2 * i + 1] = 0.5 * std::sin(0.7 * step) + (iteration == 1 ? 0.05 : 0.0);
  return f;
}

bool identical(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

using Case = std::tuple<std::string, std::string, double>;  // analysis, scheme, damping
class SolidCheckpoint : public ::testing::TestWithParam<Case> {};

TEST_P(SolidCheckpoint, RestoredModelContinuesBitForBit) {
  const auto& [analysis, scheme, damping] = GetParam();
  const fsi::Scene scene = fsi::Scene::parse(beam_scene(analysis, scheme), "beam.yaml");
  const double dt = 0.01;
  const int saved_at = 4, steps = 10;
  auto a = make(scene, dt, damping);
  const auto itf = a->interface();
  std::string bytes;
  std::vector<std::pair<fsi::SolidStepResult, std::map<std::string, double>>> reference;
  for (int n = 1; n <= steps; ++n) {
    fsi::SolidStepResult r;
    for (int k = 1; k <= 2; ++k) r = a->solve_step({n * dt, dt, n, k}, force(itf, n, k));
    auto probes = a->accept_step({n * dt, dt, n, 2});
    if (n == saved_at) bytes = a->save_checkpoint(n, n * dt);
    if (n > saved_at) reference.emplace_back(r, probes);
  }
  auto b = make(scene, dt, damping);
  b->load_checkpoint(saved_at, saved_at * dt, bytes);
  for (int n = saved_at + 1; n <= steps; ++n) {
    fsi::SolidStepResult r;
    for (int k = 1; k <= 2; ++k) r = b->solve_step({n * dt, dt, n, k}, force(itf, n, k));
    const auto probes = b->accept_step({n * dt, dt, n, 2});
    const auto& [ref_r, ref_probes] = reference[n - saved_at - 1];
    EXPECT_TRUE(identical(r.interface_displacement, ref_r.interface_displacement)) << "step " << n;
    EXPECT_TRUE(identical(r.interface_velocity, ref_r.interface_velocity)) << "step " << n;
    EXPECT_EQ(r.newton_iterations, ref_r.newton_iterations);
    for (const auto& [name, value] : ref_probes) EXPECT_EQ(probes.at(name), value) << name << " step " << n;
  }
  EXPECT_GT(std::abs(reference.back().first.interface_displacement.maxCoeff()), 1e-6);  // it did move
}

INSTANTIATE_TEST_SUITE_P(Schemes, SolidCheckpoint,
                         ::testing::Values(Case{"dynamic", "bdf1", 0.0}, Case{"dynamic", "bdf2", 0.0},
                                           Case{"dynamic", "newmark", 0.0}, Case{"dynamic", "bdf2", 50.0},
                                           Case{"dynamic", "bdf1", 50.0}, Case{"static", "bdf1", 0.0}));

TEST(SolidCheckpoint, StateOfAnotherMeshOrSchemeIsRefused) {
  const fsi::Scene scene = fsi::Scene::parse(beam_scene("dynamic", "bdf2"), "beam.yaml");
  auto a = make(scene, 0.01, 0.0);
  a->solve_step({0.01, 0.01, 1, 1}, force(a->interface(), 1, 1));
  a->accept_step({0.01, 0.01, 1, 1});
  const std::string bytes = a->save_checkpoint(1, 0.01);
  const fsi::Scene finer = fsi::Scene::parse(beam_scene("dynamic", "bdf2", 30), "beam.yaml");
  try {
    make(finer, 0.01, 0.0)->load_checkpoint(1, 0.01, bytes);
    FAIL() << "a state of another mesh was accepted";
  } catch (const fsi::StateError& e) {
    EXPECT_NE(std::string(e.what()).find("'solid.d_n' has"), std::string::npos) << e.what();
  }
  const fsi::Scene newmark = fsi::Scene::parse(beam_scene("dynamic", "newmark"), "beam.yaml");
  try {
    make(newmark, 0.01, 0.0)->load_checkpoint(1, 0.01, bytes);
    FAIL() << "a state of another scheme was accepted";
  } catch (const fsi::StateError& e) {
    EXPECT_NE(std::string(e.what()).find("'solid.scheme'"), std::string::npos) << e.what();
  }
}

}  // namespace

namespace {

// A huge or non-finite interface force must not be reported as a converged solve.
TEST(SolidOverflow, HugeInterfaceForceIsNotConverged) {
  const fsi::Scene scene = fsi::Scene::parse(beam_scene("dynamic", "bdf1"), "beam.yaml");
  for (double magnitude : {1e155, 1e200, 1e300}) {
    auto a = make(scene, 0.01, 0.0);
    Eigen::VectorXd f = force(a->interface(), 1, 1);
    f[f.size() - 1] = magnitude;
    try {
      const auto r = a->solve_step({0.01, 0.01, 1, 1}, f);
      ADD_FAILURE() << magnitude << ": solve_step returned (" << r.newton_iterations << " Newton iterations, |d| "
                    << r.interface_displacement.norm() << ")";
    } catch (const fsi::SolverError& e) {
      const std::string what = e.what();
      EXPECT_TRUE(what.find("Newton did not converge") != std::string::npos ||
                  what.find("inverted") != std::string::npos)
          << what;
    }
  }
}

}  // namespace

// A 3D solid (no interface: gravity drives it) restored from a checkpoint continues bit for bit.
TEST(SolidCheckpoint3D, RestoredModelContinuesBitForBit) {
  for (const std::string scheme : {"bdf1", "bdf2", "newmark"}) {
    const fsi::Scene scene = fsi::Scene::parse(R"(
solid:
  model: fem
  mesh: {type: box, origin: [0, 0, 0], size: [1.0, 0.1, 0.1], divisions: [8, 1, 1]}
  material: {law: neo_hookean, youngs_modulus: 1.0e4, poisson_ratio: 0.3}
  element: h8_eas
  density: 10.0
  gravity: [0, -1, 0.5]
  analysis: dynamic
  time_scheme: )" + scheme + R"(
  clamp: left
  probes: [{name: tip, point: [1.0, 0.05, 0.05]}]
)",
                                               "beam3d.yaml");
    const double dt = 0.01;
    const int saved_at = 3, steps = 7;
    auto a = make(scene, dt, 0);
    std::string bytes;
    std::vector<std::map<std::string, double>> reference;
    for (int n = 1; n <= steps; ++n) {
      a->solve_step({n * dt, dt, n, 1}, Eigen::VectorXd());
      auto probes = a->accept_step({n * dt, dt, n, 1});
      if (n == saved_at) bytes = a->save_checkpoint(n, n * dt);
      if (n > saved_at) reference.push_back(probes);
    }
    auto b = make(scene, dt, 0);
    b->load_checkpoint(saved_at, saved_at * dt, bytes);
    for (int n = saved_at + 1; n <= steps; ++n) {
      b->solve_step({n * dt, dt, n, 1}, Eigen::VectorXd());
      const auto probes = b->accept_step({n * dt, dt, n, 1});
      for (const std::string key : {"tip_x", "tip_y", "tip_z"})
        EXPECT_EQ(probes.at(key), reference[static_cast<std::size_t>(n - saved_at - 1)].at(key)) << scheme << key;
    }
    EXPECT_NE(reference.back().at("tip_z"), 0.0) << scheme;
  }
}

// Variable-step BDF2: a body in free fall under gravity moves as y = -g t^2 / 2, quadratic in t,
// which BDF2 integrates exactly on any steps once its history is exact. From the exact state at
// t = 0.2 after steps of 0.1, steps of 0.025 (a fork into 4 substeps) stay exact to round-off; the
// fixed-step formula on that history is off by several per cent. The step size is checkpointed.
TEST(SolidBdf2, VariableStepsKeepAFreeFallExact) {
  const fsi::Scene scene = fsi::Scene::parse(R"(
solid:
  model: fem
  mesh: {type: rectangle, origin: [0, 0], size: [1.0, 1.0], elements: [2, 2]}
  material: {law: saint_venant_kirchhoff, youngs_modulus: 1.0e4, poisson_ratio: 0.3}
  density: 10.0
  gravity: [0.0, -10.0]
  analysis: dynamic
  time_scheme: bdf2
  probes: [{name: c, point: [0.5, 0.5]}]
)",
                                             "fall.yaml");
  auto solid = make(scene, 0.1, 0.0);
  fsi::StateArchive state;
  solid->save_state(state);
  const Eigen::Index n = state.vector("solid.d_n").size();
  auto field = [n](double y) {  // every node's (0, y)
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
    for (Eigen::Index i = 1; i < n; i += 2) f[i] = y;
    return f;
  };
  const double g = 10.0;
  auto y = [g](double t) { return -0.5 * g * t * t; };
  state.put("solid.d_n", field(y(0.2)));
  state.put("solid.v_n", field(-g * 0.2));
  state.put("solid.a_n", field(-g));
  state.put("solid.d_nm1", field(y(0.1)));
  state.put("solid.v_nm1", field(-g * 0.1));
  state.put("solid.accepted_steps", std::int64_t{2});
  state.put("solid.dt_n", 0.1);
  solid->load_state(state);
  double t = 0.2;
  for (int step = 3; step <= 6; ++step) {
    t += 0.025;
    const fsi::StepInfo info{t, 0.025, step, 0};
    solid->solve_step(info, Eigen::VectorXd());
    const auto probes = solid->accept_step(info);
    EXPECT_NEAR(probes.at("c_y"), y(t), 1e-12) << "t = " << t;
    EXPECT_NEAR(probes.at("c_x"), 0.0, 1e-12);
  }
  fsi::StateArchive after;
  solid->save_state(after);
  EXPECT_EQ(after.real("solid.dt_n"), 0.025);
}
