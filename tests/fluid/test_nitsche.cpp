// Nitsche interface (the seed paper's fluid weak form): a rotating cylinder in the DFG
// channel, its wall velocity imposed (a) strongly and (b) through the Nitsche interface
// with gamma_N2 = +1 and -1. Forces must agree to within the discretisation error; the
// interface loads must satisfy the contract (f_sigma consistent with the force, f_v ~ M_G v_s).
#include <gtest/gtest.h>

#include "fsi/common/gmsh_reader.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"

namespace {

using namespace fsi::fluid;

const Eigen::Vector2d kCentre(0.2, 0.2);
constexpr double kOmega = 4.0;  // rad/s: wall speed 0.2, comparable to U_bar

Eigen::Vector2d rotation(const Eigen::Vector2d& x) {
  const Eigen::Vector2d r = x - kCentre;
  return kOmega * Eigen::Vector2d(-r.y(), r.x());
}

FluidMesh coarse_dfg_mesh() {
  const auto msh = mesh_geo(FSI_FLUID_SOURCE_DIR "/configs/meshes/dfg_cylinder.geo", {{"h", 0.04}, {"hc", 0.005}},
                            std::filesystem::temp_directory_path() / "fsi_fluid_test_meshes");
  return FluidMesh::from_gmsh(fsi::read_gmsh(msh));
}

NavierStokesSolver make_solver(const FluidMesh& mesh, bool nitsche, double penalty, double symmetry) {
  FlowParameters p;
  p.density = 1;
  p.viscosity = 1e-3;
  p.scheme = TimeScheme::Steady;
  p.max_iterations = 60;
  p.tolerance = 1e-10;
  p.nitsche_penalty = penalty;
  p.nitsche_symmetry = symmetry;
  NavierStokesSolver s(mesh, p);
  s.add_dirichlet("inlet", [](const Eigen::Vector2d& x, double) {
    return Eigen::Vector2d(4 * 0.3 * x.y() * (0.41 - x.y()) / (0.41 * 0.41), 0);
  });
  s.add_dirichlet("walls", [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); });
  if (nitsche)
    s.set_interface({"cylinder"});
  else
    s.add_dirichlet("cylinder", [](const Eigen::Vector2d& x, double) { return rotation(x); });
  return s;
}

Eigen::VectorXd interface_velocity(const NavierStokesSolver& s) {
  Eigen::VectorXd v(2 * static_cast<Eigen::Index>(s.interface_nodes().size()));
  for (std::size_t i = 0; i < s.interface_nodes().size(); ++i)
    v.segment<2>(2 * static_cast<Eigen::Index>(i)) = rotation(s.mesh().nodes.row(s.interface_nodes()[i]).transpose());
  return v;
}

TEST(Nitsche, RotatingCylinderForcesMatchStrongDirichlet) {
  const auto mesh = coarse_dfg_mesh();
  auto strong = make_solver(mesh, false, 0, -1);
  strong.solve(1, 1, mesh.nodes, {});
  const Eigen::Vector2d f_strong = strong.force({"cylinder"});
  const double scale = 2 / (0.2 * 0.2 * 0.1);
  std::printf("strong:        C_D %.5f  C_L %.5f\n", scale * f_strong.x(), scale * f_strong.y());
  EXPECT_GT(std::abs(f_strong.y()), 0.05 * f_strong.x()) << "rotation should produce a clear Magnus lift";

  for (double symmetry : {+1.0, -1.0}) {
    for (double penalty : {10.0, 100.0}) {
      auto weak = make_solver(mesh, true, penalty, symmetry);
      const Eigen::VectorXd vs = interface_velocity(weak);
      const auto report = weak.solve(1, 1, mesh.nodes, vs);
      ASSERT_LT(report.change, 1e-8);
      const Eigen::Vector2d f = weak.force({"cylinder"});
      std::printf("gamma_N2 %+g gamma_N1 %5.1f: C_D %.5f  C_L %.5f\n", symmetry, penalty, scale * f.x(), scale * f.y());
      EXPECT_NEAR(f.x(), f_strong.x(), 0.01 * f_strong.x()) << "gamma_N2 " << symmetry << " gamma_N1 " << penalty;
      EXPECT_NEAR(f.y(), f_strong.y(), 0.03 * std::abs(f_strong.y()))
          << "gamma_N2 " << symmetry << " gamma_N1 " << penalty;

      // Contract: f_v = int N^T v_f ~ M_G v_s (the slip is small), and the coupler's
      // F* = f_sigma - gamma_N1 (f_v - M_G v_s) is exactly the consistent reaction, whose sum
      // is minus the force on the body; f_sigma alone (= int N^T sigma_h n) is close to it.
      const Eigen::VectorXd fs = weak.interface_traction();
      const Eigen::VectorXd fv = weak.interface_velocity_integral();
      double slip = 0, norm = 0;
      const auto& seg = weak.interface_segments();
      Eigen::VectorXd mv = Eigen::VectorXd::Zero(fv.size());
      for (Eigen::Index s = 0; s < seg.rows(); ++s) {
        const int a = seg(s, 0), b = seg(s, 1);
        const double len =
            (mesh.nodes.row(weak.interface_nodes()[a]) - mesh.nodes.row(weak.interface_nodes()[b])).norm();
        mv.segment<2>(2 * a) += len / 6 * (2 * vs.segment<2>(2 * a) + vs.segment<2>(2 * b));
        mv.segment<2>(2 * b) += len / 6 * (vs.segment<2>(2 * a) + 2 * vs.segment<2>(2 * b));
      }
      slip = (fv - mv).norm();
      norm = mv.norm();
      EXPECT_LT(slip, 0.05 * norm) << "velocity constraint badly imposed";
      const Eigen::VectorXd f_star = fs - penalty * (fv - mv);
      Eigen::Vector2d total = Eigen::Vector2d::Zero(), total_sigma = Eigen::Vector2d::Zero();
      for (Eigen::Index i = 0; i < fs.size() / 2; ++i) {
        total += f_star.segment<2>(2 * i);
        total_sigma += fs.segment<2>(2 * i);
      }
      EXPECT_NEAR(-total.x(), f.x(), 1e-10);
      EXPECT_NEAR(-total.y(), f.y(), 1e-10);
      EXPECT_NEAR(-total_sigma.x(), f.x(), 0.05 * f.x());
    }
  }
}

TEST(Nitsche, SolidBodyTranslationOfTheWholeDomainIsExact) {
  // Uniform flow through a box whose every wall moves with the same velocity, imposed by
  // Nitsche on all four sides (pressure pinned): the exact solution u = const, p = 0 is
  // reproduced to round-off for both gamma_N2.
  const auto mesh = FluidMesh::rectangle(0, 1, 0, 1, 8, 8);
  for (double symmetry : {+1.0, -1.0}) {
    FlowParameters p;
    p.viscosity = 0.01;
    p.scheme = TimeScheme::BDF1;
    p.nitsche_penalty = 10;
    p.nitsche_symmetry = symmetry;
    NavierStokesSolver s(mesh, p);
    s.set_interface({"left", "right", "bottom", "top"});
    s.set_pressure_reference({0.5, 0.5}, [](double) { return 0.0; });
    Eigen::MatrixX2d initial(mesh.node_count(), 2);
    initial.col(0).setConstant(0.3);
    initial.col(1).setConstant(-0.2);
    s.set_initial_velocity(initial);
    Eigen::VectorXd vs(2 * static_cast<Eigen::Index>(s.interface_nodes().size()));
    for (Eigen::Index i = 0; i < vs.size() / 2; ++i) vs.segment<2>(2 * i) << 0.3, -0.2;
    s.solve(0.1, 0.1, mesh.nodes, vs);
    const auto v = s.velocity();
    EXPECT_NEAR((v.col(0).array() - 0.3).abs().maxCoeff(), 0.0, 1e-10);
    EXPECT_NEAR((v.col(1).array() + 0.2).abs().maxCoeff(), 0.0, 1e-10);
    EXPECT_NEAR(s.pressure().cwiseAbs().maxCoeff(), 0.0, 1e-10);
  }
}

}  // namespace

namespace {
// The interface mass sent to the coupler (the penalty term's operator, from which f_v = M_f v_f
// is computed) lives on the interface of this solve (default) or of the last accepted step
// (penalty_geometry: step_start). Returns its total, the interface's length.
double interface_mass_after_dilation(bool step_start) {
  const auto mesh = coarse_dfg_mesh();
  FlowParameters q;
  q.density = 1;
  q.viscosity = 1e-3;
  q.scheme = TimeScheme::BDF1;
  q.nitsche_penalty = 100.0;
  q.penalty_on_step_start = step_start;
  NavierStokesSolver t(mesh, q);
  t.add_dirichlet("inlet", [](const Eigen::Vector2d& x, double) {
    return Eigen::Vector2d(4 * 0.3 * x.y() * (0.41 - x.y()) / (0.41 * 0.41), 0);
  });
  t.add_dirichlet("walls", [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); });
  t.set_interface({"cylinder"});
  // The whole mesh dilated by 1 % about the cylinder's centre: every interface edge 1 % longer.
  Eigen::MatrixX2d x = mesh.nodes;
  for (Eigen::Index i = 0; i < x.rows(); ++i) x.row(i) = kCentre.transpose() + 1.01 * (x.row(i) - kCentre.transpose());
  t.solve(0.01, 0.01, x, interface_velocity(t));
  return Eigen::MatrixXd(t.interface_mass()).sum();  // the interface's length in that configuration
}
}  // namespace

TEST(Nitsche, InterfaceMassIsThePenaltyOperatorInItsConfiguration) {
  const double current = interface_mass_after_dilation(false);
  const double start = interface_mass_after_dilation(true);
  EXPECT_NEAR(current / start, 1.01, 1e-12);                     // the polygon's perimeter scales exactly
  EXPECT_NEAR(start, 2 * M_PI * 0.05, 0.002 * 2 * M_PI * 0.05);  // the undeformed circle (polygon)
}

// The Robin interface condition of the explicit Robin-Neumann coupling (FlowSolver::solve with
// a RobinCondition), both elements. Plane Couette flow in [0, 2] x [0, 1]: walls left, right
// and bottom strong (u = (U y, 0)), Robin on the top. sigma n = (mu U, -p) there, so the
// condition sigma n + alpha v = alpha v* + t* with v* = (V, 0), t* = (tau, -p0) has the exact
// solution u = (U y, 0), p = p0, U = (alpha V + tau) / (alpha + mu), which both elements
// reproduce to round-off (linear velocity, constant pressure). Then arbitrary nodal v* and f*:
// the lumped identity f_sigma_j + A_j v_j = A_j v*_j + f*_j at every node without a strong
// condition, to solver tolerance.
TEST(Robin, CouetteFlowAndTheLumpedIdentityOnBothElements) {
  const double mu = 0.1, alpha = 2.0, V = 1.0, tau = 0.05, p0 = 0.7;
  const double U = (alpha * V + tau) / (alpha + mu);
  const auto mesh = FluidMesh::rectangle(0, 2, 0, 1, 8, 4);
  for (const char* element : {"p1p1", "p2p1"}) {
    SCOPED_TRACE(element);
    FlowParameters p;
    p.viscosity = mu;
    p.scheme = TimeScheme::BDF1;
    p.max_iterations = 30;
    p.tolerance = 1e-13;
    p.nitsche_penalty = 100;        // Nitsche's terms: not in a Robin solve
    p.reuse_factorisation = false;  // direct solves: the identity to round-off
    FlowSolver s(mesh, p, element);
    const auto couette = [U](const Eigen::Vector2d& x, double) { return Eigen::Vector2d(U * x.y(), 0); };
    for (const char* wall : {"left", "right", "bottom"}) s.add_dirichlet(wall, couette);
    s.set_interface({"top"});
    const auto& nodes = s.mesh().nodes;
    Eigen::MatrixX2d initial(nodes.rows(), 2);
    for (Eigen::Index i = 0; i < nodes.rows(); ++i) initial.row(i) = couette(nodes.row(i).transpose(), 0).transpose();
    s.set_initial_velocity(initial);
    const auto n = static_cast<Eigen::Index>(s.interface_nodes().size());
    const Eigen::VectorXd lumped = Eigen::MatrixXd(s.interface_mass()).rowwise().sum();  // int N_j
    EXPECT_NEAR(lumped.sum(), 2.0, 1e-12);
    fsi::RobinCondition r;
    r.coefficient = Eigen::VectorXd::Constant(n, alpha);
    r.velocity = Eigen::VectorXd::Zero(2 * n);
    r.traction = Eigen::VectorXd::Zero(2 * n);
    for (Eigen::Index j = 0; j < n; ++j) {
      r.velocity(2 * j) = V;
      r.traction.segment<2>(2 * j) = lumped(j) * Eigen::Vector2d(tau, -p0);
    }
    s.solve_robin(0.1, 0.1, nodes, r);
    const auto v = s.velocity();
    for (Eigen::Index i = 0; i < nodes.rows(); ++i) {
      EXPECT_NEAR(v(i, 0), U * nodes(i, 1), 1e-11);
      EXPECT_NEAR(v(i, 1), 0, 1e-11);
    }
    EXPECT_NEAR((s.pressure().array() - p0).abs().maxCoeff(), 0, 1e-10);
    // f_sigma = int N_j sigma n, exactly (the reaction; no penalty part), at the nodes without
    // a strong condition (the two corners' reactions hold the walls' too).
    const Eigen::VectorXd f = s.interface_traction();
    const auto free = [&](Eigen::Index j) {
      const double x = nodes(s.interface_nodes()[static_cast<std::size_t>(j)], 0);
      return x > 1e-12 && x < 2 - 1e-12;
    };
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!free(j)) continue;
      EXPECT_NEAR(f(2 * j), mu * U * lumped(j), 1e-11);
      EXPECT_NEAR(f(2 * j + 1), -p0 * lumped(j), 1e-11);
    }

    // Arbitrary nodal data (a later step): the identity holds node by node.
    for (Eigen::Index j = 0; j < n; ++j) {
      const double x = nodes(s.interface_nodes()[static_cast<std::size_t>(j)], 0);
      r.coefficient(j) = alpha * (1 + 0.5 * x);
      r.velocity.segment<2>(2 * j) << std::sin(3 * x), 0.2 * std::cos(2 * x);
      r.traction.segment<2>(2 * j) << 0.01 * x, -0.05 * (1 + x * x);
    }
    s.accept();
    s.solve_robin(0.2, 0.1, nodes, r);
    const Eigen::VectorXd fs = s.interface_traction();
    int checked = 0;
    double worst = 0, scale = 0;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!free(j)) continue;
      const int node = s.interface_nodes()[static_cast<std::size_t>(j)];
      const double a = r.coefficient(j) * lumped(j);
      const Eigen::Vector2d lhs = fs.segment<2>(2 * j) + a * s.velocity().row(node).transpose();
      const Eigen::Vector2d rhs = a * r.velocity.segment<2>(2 * j) + r.traction.segment<2>(2 * j);
      worst = std::max(worst, (lhs - rhs).cwiseAbs().maxCoeff());
      scale = std::max(scale, rhs.cwiseAbs().maxCoeff());
      ++checked;
    }
    EXPECT_EQ(checked, std::string(element) == "p1p1" ? 7 : 15);
    EXPECT_LT(worst, 1e-12 * scale);
    EXPECT_GT(s.velocity().col(1).cwiseAbs().maxCoeff(), 1e-3);  // the data did move the fluid
  }
}
