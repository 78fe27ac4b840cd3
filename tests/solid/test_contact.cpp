// Contact with rigid obstacles (contact.hpp): a block pressed onto a wall rests at the penalty's
// closed-form gap, Newton keeps its quadratic rate through contact onset, nothing changes while
// every gap stays above g_c, and the scene keys refuse what they cannot use.
#include <gtest/gtest.h>

#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>

#include "fsi/solid/contact.hpp"
#include "fsi/solid/fem_solid.hpp"
#include "fsi/solid/solid_system.hpp"

using namespace fsi::solid;

namespace {

// A block [0, 1] x [y0, y0 + 0.2] (10 x 4 Q4, or 10 x 4 x 2 Hex8 of depth 0.2), left face held
// in x only, pressed by a dead traction T on its top onto the wall y = 0 (normal +y).
struct Block {
  SolidMesh mesh;
  std::vector<char> fixed;
  std::unique_ptr<SolidSystem> system;
  Eigen::VectorXd load;  // the traction's nodal forces
  Obstacle wall;
  double traction = 0, top_area = 0;
};

Block make_block(int dim, double y0, double traction, double gap) {
  Block b;
  const double E = 1e4, nu = 0.3;
  b.mesh = dim == 2 ? rectangle_mesh(0, y0, 1, 0.2, 10, 4)
                    : box_mesh(Eigen::Vector3d(0, y0, 0), Eigen::Vector3d(1, 0.2, 0.2), 10, 4, 2);
  const int n = b.mesh.num_nodes();
  b.fixed.assign(static_cast<std::size_t>(dim * n), 0);
  for (int node : b.mesh.facet_nodes({"left"})) b.fixed[static_cast<std::size_t>(dim * node)] = 1;
  if (dim == 3)  // plane strain through the depth: z held on the back and front faces
    for (int node : b.mesh.facet_nodes({"back", "front"})) b.fixed[static_cast<std::size_t>(3 * node + 2)] = 1;
  const auto c = ElasticConstants::from_youngs(E, nu);
  if (dim == 2)
    b.system = std::make_unique<SolidSystem>(b.mesh, make_material<2>("neo_hookean", c), 1.0, b.fixed);
  else
    b.system = std::make_unique<SolidSystem>(b.mesh, make_material<3>("neo_hookean", c), 1.0, b.fixed);
  b.wall.point = Eigen::VectorXd::Zero(dim);
  b.wall.normal = Eigen::VectorXd::Unit(dim, 1);
  b.wall.contact_gap = gap;
  b.wall.stiffness = E / 0.05;  // E / h
  b.system->set_contact(std::make_shared<ObstacleContact>(
      b.mesh, std::vector<Obstacle>{b.wall}, std::vector<std::vector<Facet>>{b.mesh.facets({"bottom"})}, b.fixed));
  // The traction's nodal forces: the lumped measure of the top facets times T (exact for a constant traction).
  const Eigen::VectorXd top = lumped_facet_measure(b.mesh, b.mesh.facets({"top"}));
  b.load = Eigen::VectorXd::Zero(dim * n);
  for (int i = 0; i < n; ++i) b.load(dim * i + 1) = -traction * top(i);
  b.traction = traction;
  b.top_area = top.sum();
  return b;
}

double sum_y(const Eigen::VectorXd& v, int dim) {
  double s = 0;
  for (Eigen::Index i = 1; i < v.size(); i += dim) s += v(i);
  return s;
}

// Newton on the free dofs by hand (the system's assemble), keeping every residual norm.
std::vector<double> newton_residuals(SolidSystem& sys, Eigen::VectorXd& d, const Eigen::VectorXd& f, const TimeTerms& t,
                                     int iterations) {
  std::vector<double> out;
  SparseMatrix K;
  Eigen::VectorXd r;
  std::vector<int> free;
  for (int i = 0; i < sys.num_dofs(); ++i)
    if (sys.equation(i) >= 0) free.push_back(i);
  for (int it = 0; it < iterations; ++it) {
    sys.assemble(d, f, t, K, r);
    out.push_back(r.norm());
    if (r.norm() < 1e-11 * out.front()) break;
    Eigen::SparseLU<SparseMatrix> lu(K);
    const Eigen::VectorXd dd = lu.solve(-r);
    for (std::size_t i = 0; i < free.size(); ++i) d(free[i]) += dd(static_cast<Eigen::Index>(i));
  }
  return out;
}

}  // namespace

TEST(ContactPressure, SmoothAtTheContactGapAndClosedFormBelow) {
  Obstacle o;
  o.contact_gap = 0.01, o.stiffness = 1e6;
  EXPECT_EQ(contact_pressure(o, 0.01), 0.0);
  EXPECT_EQ(contact_pressure(o, 0.5), 0.0);
  EXPECT_EQ(contact_pressure_derivative(o, 0.01), 0.0);
  EXPECT_NEAR(contact_pressure(o, 0.0), 1e6 * 0.01, 1e-9);  // p(0) = k_n g_c
  const double g = 0.004, h = 1e-7;                         // dp/dg against a central difference
  EXPECT_NEAR(contact_pressure_derivative(o, g), (contact_pressure(o, g + h) - contact_pressure(o, g - h)) / (2 * h),
              1e-6 * std::abs(contact_pressure_derivative(o, g)));
}

// Static equilibrium: a homogeneous compression in which every bottom node has the gap
// g = g_c - sqrt(T g_c / k_n) and the contact force balances the traction, T |top| = p(g) |bottom|.
class BlockOnWall : public ::testing::TestWithParam<int> {};

TEST_P(BlockOnWall, RestsAtThePenaltyEquilibriumGap) {
  const int dim = GetParam();
  const double T = 50, gc = 0.01;
  Block b = make_block(dim, 0.1, T, gc);
  // Static: the tangent is singular until the block touches, so Newton starts from the block
  // moved to g = g_c / 2 (a rigid translation).
  Eigen::VectorXd d = Eigen::VectorXd::Zero(b.system->num_dofs());
  for (int i = 0; i < b.mesh.num_nodes(); ++i) d(dim * i + 1) = -(0.1 - 0.5 * gc);
  NewtonOptions opt;
  opt.residual_tolerance = 1e-13;
  opt.increment_tolerance = 0;
  const NewtonReport rep = b.system->solve(d, b.load, TimeTerms{}, opt);
  ASSERT_TRUE(rep.converged);
  const double g_exact = gc - std::sqrt(T * gc / b.wall.stiffness);
  for (int node : b.mesh.facet_nodes({"bottom"})) {
    const double g = b.mesh.nodes(node, 1) + d(dim * node + 1);
    EXPECT_NEAR(g, g_exact, 1e-8 * g_exact) << "node " << node;
  }
  const ContactState s = b.system->contact()->measure(d);
  EXPECT_NEAR(s.min_gap, g_exact, 1e-8 * g_exact);
  EXPECT_EQ(s.active_nodes, static_cast<int>(b.mesh.facet_nodes({"bottom"}).size()));
  EXPECT_NEAR(s.force(1), T * b.top_area, 1e-8 * T * b.top_area);  // force balance
  EXPECT_NEAR(sum_y(b.load, dim), -T * b.top_area, 1e-12 * T * b.top_area);
}

// One dynamic step from rest, 0.1 above the wall: Newton's first iterates are out of contact,
// the last ones in it; the rate q = log(r_{k+1} / r_k) / log(r_k / r_{k-1}) ends near 2.
TEST_P(BlockOnWall, NewtonQuadraticThroughContactOnset) {
  const int dim = GetParam();
  const double T = 50, gc = 0.01, dt = 0.03;  // a free fall of T / (rho h) dt^2 = 0.225 in one step
  Block b = make_block(dim, 0.1, T, gc);
  TimeTerms t;  // BDF1 from rest: a = d / dt^2
  t.mass_coefficient = 1 / (dt * dt);
  t.damping_coefficient = 1 / dt;
  Eigen::VectorXd d = Eigen::VectorXd::Zero(b.system->num_dofs());
  const ContactState start = b.system->contact()->measure(d);
  ASSERT_EQ(start.active_nodes, 0);
  const auto r = newton_residuals(*b.system, d, b.load, t, 30);
  const ContactState end = b.system->contact()->measure(d);
  EXPECT_GT(end.active_nodes, 0);
  EXPECT_LT(end.min_gap, gc);
  ASSERT_GE(r.size(), 4u);
  EXPECT_LT(r.back(), 1e-11 * r.front());
  // The rate over the last three residuals above round-off (1e-14 of the largest).
  const double largest = *std::max_element(r.begin(), r.end());
  std::size_t last = r.size() - 1;
  while (last > 2 && r[last] < 1e-14 * largest) --last;
  const double q = std::log(r[last] / r[last - 1]) / std::log(r[last - 1] / r[last - 2]);
  std::printf("%dD: %zu Newton iterations, residuals", dim, r.size() - 1);
  for (double x : r) std::printf(" %.2e", x);
  std::printf("; rate %.2f\n", q);
  EXPECT_GT(q, 1.8);
  EXPECT_LT(q, 2.5);
}

// Above g_c the obstacle adds nothing: the residual is the same to the last bit.
TEST_P(BlockOnWall, NoForceAboveTheContactGap) {
  const int dim = GetParam();
  Block with = make_block(dim, 0.1, 50, 0.01);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(with.system->num_dofs());
  for (int i = 0; i < with.mesh.num_nodes(); ++i) d(dim * i + 1) = -0.09 + 1e-4 * i / with.mesh.num_nodes();
  const Eigen::VectorXd r1 = with.system->residual(d, with.load, TimeTerms{});
  with.system->set_contact(nullptr);
  const Eigen::VectorXd r0 = with.system->residual(d, with.load, TimeTerms{});
  EXPECT_EQ((r1 - r0).cwiseAbs().maxCoeff(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Dim, BlockOnWall, ::testing::Values(2, 3),
                         [](const auto& info) { return std::to_string(info.param) + "D"; });

// A node that starts inside the obstacle is refused; nodes within g_c of it at the start
// (next to a clamp) are left out.
TEST(ObstacleContact, RefusesAStartInsideAndLeavesOutNodesWithinTheGap) {
  const SolidMesh mesh = rectangle_mesh(0, 0, 1, 0.2, 10, 4);
  std::vector<char> fixed(static_cast<std::size_t>(2 * mesh.num_nodes()), 0);
  Obstacle o;
  o.point = Eigen::Vector2d(0, 0.05);
  o.normal = Eigen::Vector2d(0, 2);  // normalised by the constructor
  o.contact_gap = 0.01, o.stiffness = 1;
  EXPECT_THROW(ObstacleContact(mesh, {o}, {mesh.facets({"left"})}, fixed), ObstacleError);
  o.point = Eigen::Vector2d(0, -0.005);  // the bottom row starts 0.005 < g_c away
  const ObstacleContact c(mesh, {o}, {mesh.facets({"left", "bottom"})}, fixed);
  EXPECT_EQ(c.candidates(0), 4);  // the left edge above its bottom node
  EXPECT_EQ(c.excluded(0), 11);   // the bottom row
  EXPECT_EQ(c.obstacles()[0].normal, Eigen::Vector2d(0, 1));
}

// The scene: an obstacle that holds part of the solid at t = 0 is refused at its key's line;
// one the solid never comes near changes nothing; the statistics cross a checkpoint.
namespace {
std::string block_scene(const std::string& obstacles) {
  return R"(
solid:
  model: fem
  mesh: {type: rectangle, origin: [0, 0.1], size: [1.0, 0.2], elements: [10, 4]}
  material: {law: neo_hookean, youngs_modulus: 1.0e4, poisson_ratio: 0.3}
  density: 1.0
  analysis: dynamic
  time_scheme: bdf1
  gravity: [0, -10]
  supports: [{boundary: left, fixed: [x]}]
  interface: top
  probes: [{name: c, point: [0.5, 0.1]}]
)" + obstacles;
}

struct SceneRun {
  std::vector<std::map<std::string, double>> probes;
  std::map<std::string, double> diagnostics;
};

// `steps` steps of 0.02 from `from` (a checkpoint, or empty).
SceneRun run_block(const std::string& obstacles, int steps, fsi::StateArchive* save_at_end = nullptr,
                   const fsi::StateArchive* from = nullptr, int first = 1) {
  const auto scene = fsi::Scene::parse(block_scene(obstacles), "block.yaml");
  FemSolid solid;
  solid.configure(scene.section("solid"), fsi::SolidSetup{0.02, 1, 0, {}});
  if (from) solid.load_state(*from);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(solid.interface().nodes()));
  SceneRun r;
  for (int n = first; n < first + steps; ++n) {
    const fsi::StepInfo info{n * 0.02, 0.02, n, 0};
    solid.solve_step(info, zero);
    r.probes.push_back(solid.accept_step(info));
  }
  if (save_at_end) solid.save_state(*save_at_end);
  r.diagnostics = solid.diagnostics();
  return r;
}
}  // namespace

TEST(ObstacleScene, RefusedWhereItHoldsTheSolidAtTheStart) {
  const auto scene = fsi::Scene::parse(
      block_scene("  obstacles:\n    - {point: [0, 0.15], normal: [0, 1], contact_gap: 0.01}\n"), "block.yaml");
  FemSolid solid;
  try {
    solid.configure(scene.section("solid"), fsi::SolidSetup{0.02, 1, 0, {}});
    FAIL() << "expected ConfigError";
  } catch (const fsi::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("block.yaml:14:8: 'solid.obstacles[0].point' puts the obstacle over"), std::string::npos)
        << what;
    EXPECT_NE(what.find("solid.obstacles"), std::string::npos) << what;
    EXPECT_NE(what.find("must start outside every obstacle"), std::string::npos) << what;
  }
}

TEST(ObstacleScene, FarObstacleChangesNothingAndStatisticsCrossACheckpoint) {
  // Falling under gravity 10 for 0.4 s: 0.8, so the block (0.1 above y = 0) meets the wall.
  const std::string wall = "  obstacles: [{point: [0, 0], normal: [0, 1], contact_gap: 0.01}]\n";
  const std::string far = "  obstacles: [{point: [0, -5], normal: [0, 1], contact_gap: 0.01}]\n";
  const SceneRun none = run_block("", 20), unused = run_block(far, 20);
  ASSERT_EQ(none.probes.size(), unused.probes.size());
  for (std::size_t i = 0; i < none.probes.size(); ++i) EXPECT_EQ(none.probes[i], unused.probes[i]) << "step " << i;
  EXPECT_TRUE(none.diagnostics.empty());
  EXPECT_EQ(unused.diagnostics.at("contact_active_steps"), 0);

  const SceneRun whole = run_block(wall, 20);
  EXPECT_GT(whole.diagnostics.at("contact_active_steps"), 0);
  EXPECT_LT(whole.diagnostics.at("contact_min_gap"), 0.01);
  EXPECT_GT(whole.diagnostics.at("contact_max_force"), 0);
  fsi::StateArchive at10;
  const SceneRun head = run_block(wall, 10, &at10);
  ASSERT_GT(head.diagnostics.at("contact_active_steps"), 0);  // the checkpoint is taken in contact
  const SceneRun tail = run_block(wall, 10, nullptr, &at10, 11);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(tail.probes[i], whole.probes[10 + i]) << "step " << 11 + i;
  EXPECT_EQ(tail.diagnostics, whole.diagnostics);
}
