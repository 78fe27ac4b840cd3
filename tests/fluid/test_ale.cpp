// ALE: the mesh velocity enters the convective term and the BDF time derivative
// consistently, so a linear flow is reproduced exactly on a moving mesh; the harmonic
// mesh extension moves the interior with the interface; a tangled mesh is reported; the
// FluidModel moves its mesh with the interface displacement.
#include <gtest/gtest.h>

#include <cmath>

#include "fsi/common/config.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"

namespace {

using namespace fsi::fluid;

Eigen::MatrixX2d wobble(const FluidMesh& mesh, double t, double amplitude) {
  Eigen::MatrixX2d x = mesh.nodes;
  for (int i = 0; i < mesh.node_count(); ++i) {
    const double bump = std::sin(M_PI * mesh.nodes(i, 0)) * std::sin(M_PI * mesh.nodes(i, 1));
    x(i, 0) += amplitude * bump * std::sin(7 * t);
    x(i, 1) += amplitude * bump * std::cos(5 * t) * 0.7;
  }
  return x;
}

class CouetteOnMovingMesh : public ::testing::TestWithParam<TimeScheme> {};

TEST_P(CouetteOnMovingMesh, IsReproducedExactly) {
  // u = (y, 0), p = 0 solves Navier-Stokes in [0,1]^2; its nodal values change as the nodes
  // move, which the ALE term -(w . grad) u must cancel exactly for linear fields.
  const auto mesh = FluidMesh::rectangle(0, 1, 0, 1, 10, 10);
  FlowParameters p;
  p.viscosity = 0.01;
  p.scheme = GetParam();
  p.reuse_factorisation = false;  // direct solves: the check is to round-off
  NavierStokesSolver s(mesh, p);
  auto couette = [](const Eigen::Vector2d& x, double) { return Eigen::Vector2d(x.y(), 0); };
  for (const char* g : {"left", "bottom", "top"}) s.add_dirichlet(g, couette);
  Eigen::MatrixX2d initial(mesh.node_count(), 2);
  for (int i = 0; i < mesh.node_count(); ++i) initial.row(i) << mesh.nodes(i, 1), 0;
  s.set_initial_velocity(initial);
  const double dt = 0.05;
  double max_err = 0, max_motion = 0;
  for (int n = 1; n <= 10; ++n) {
    const auto x = wobble(mesh, n * dt, 0.08);
    s.solve(n * dt, dt, x, {});
    s.accept();
    const auto v = s.velocity();
    for (int i = 0; i < mesh.node_count(); ++i)
      max_err = std::max(max_err, (v.row(i) - Eigen::RowVector2d(x(i, 1), 0)).norm());
    max_err = std::max(max_err, s.pressure().cwiseAbs().maxCoeff());
    max_motion = std::max(max_motion, (x - mesh.nodes).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(max_motion, 0.02);
  EXPECT_LT(max_err, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Schemes, CouetteOnMovingMesh, ::testing::Values(TimeScheme::BDF1, TimeScheme::BDF2));

TEST(MeshMotion, HarmonicExtensionFollowsTheInterfaceAndKeepsBoundariesFixed) {
  const auto mesh = FluidMesh::rectangle(0, 1, 0, 1, 12, 12);
  // "Interface": the bottom wall moves up rigidly; the top is fixed.
  const auto moving = mesh.boundary_nodes({"bottom"});
  MeshMotion motion(mesh, moving, mesh.boundary_nodes({"top"}));
  Eigen::VectorXd d(2 * static_cast<Eigen::Index>(moving.size()));
  for (Eigen::Index i = 0; i < d.size() / 2; ++i) d.segment<2>(2 * i) << 0, 0.1;
  const auto u = motion.extend(d);
  for (int i = 0; i < mesh.node_count(); ++i) {
    const double y = mesh.nodes(i, 1);
    if (y > 1 - 1e-12) {
      EXPECT_EQ(u(i, 1), 0.0);
    }
    if (y < 1e-12) {
      EXPECT_DOUBLE_EQ(u(i, 1), 0.1);
    }
    EXPECT_GE(u(i, 1), -1e-12);
    EXPECT_LE(u(i, 1), 0.1 + 1e-12);  // maximum principle
  }
}

TEST(NavierStokesSolver, InvertedElementIsReportedWithTimeAndPlace) {
  const auto mesh = FluidMesh::rectangle(0, 1, 0, 1, 4, 4);
  FlowParameters p;
  p.scheme = TimeScheme::BDF1;
  NavierStokesSolver s(mesh, p);
  s.add_dirichlet("bottom", [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); });
  Eigen::MatrixX2d x = mesh.nodes;
  x.row(6) << 0.9, 0.9;  // an interior node dragged across its neighbours
  try {
    s.solve(0.25, 0.25, x, {});
    FAIL() << "expected a SolverError";
  } catch (const fsi::SolverError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("t = 0.25"), std::string::npos) << what;
    EXPECT_NE(what.find("inverted"), std::string::npos) << what;
  }
}

TEST(NavierStokesFluid, MovesItsMeshWithTheInterfaceDisplacement) {
  // DFG channel with the cylinder as the Nitsche interface, translated rigidly upwards.
  const std::string text = std::string(R"(
fluid:
  model: fem
  mesh: {geo: )") + FSI_FLUID_SOURCE_DIR +
                           R"(/configs/meshes/dfg_cylinder.geo, size: 0.08, parameters: {hc: 0.01}}
  density: 1.0
  viscosity: 0.001
  scheme: bdf2
  inflow: [{group: inlet, max_velocity: 0.3}]
  walls: [walls]
  outlet: [outlet]
  interface: {groups: [cylinder], penalty: 10.0, symmetry: -1}
  forces: [{name: cyl, groups: [cylinder]}]
)";
  auto scene = fsi::Scene::parse(text, "inline");
  fsi::FluidSetup setup;
  setup.dt = 0.01;
  setup.end_time = 0.05;
  NavierStokesFluid model;
  EXPECT_EQ(scene.section("fluid").get<std::string>("model"), "fem");  // the factory's key
  model.configure(scene.section("fluid"), setup);
  scene.check_all_used("fluid");
  const auto iface = model.interface();
  ASSERT_GT(iface.nodes(), 10u);
  EXPECT_EQ(iface.segments.size(), iface.nodes());  // a closed curve
  const auto n = static_cast<Eigen::Index>(iface.nodes());
  Eigen::VectorXd d = Eigen::VectorXd::Zero(2 * n), v = Eigen::VectorXd::Zero(2 * n);
  const double speed = 0.1;
  for (int step = 1; step <= 5; ++step) {
    const fsi::StepInfo info{step * 0.01, 0.01, step, 1};
    for (Eigen::Index i = 0; i < n; ++i) {
      d(2 * i + 1) = speed * info.time;
      v(2 * i + 1) = speed;
    }
    const auto loads = model.solve_step(info, d, v);
    ASSERT_EQ(loads.traction_force.size(), 2 * n);
    ASSERT_TRUE(loads.traction_force.allFinite());
    // The fluid at the interface moves with the body (weakly): f_v ~ M_G v_s, upward.
    EXPECT_GT(loads.velocity_integral(Eigen::seqN(1, n, 2)).sum(), 0.5 * speed * 2 * M_PI * 0.05);
    const auto probes = model.accept_step(info);
    EXPECT_TRUE(std::isfinite(probes.at("cyl_drag")));
  }
  const auto& x = model.solver().positions();
  const auto& ref = model.solver().mesh().nodes;
  const int node = model.solver().interface_nodes().front();
  EXPECT_NEAR(x(node, 1) - ref(node, 1), 0.005, 1e-12);
}

}  // namespace
