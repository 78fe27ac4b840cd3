// Taylor-Hood P2/P1: shape functions, the Kovasznay solution with its observed rates
// (velocity L2 3, pressure L2 2) on a fixed and on a moving (ALE, BDF2) mesh, Newton's
// quadratic convergence, and the Nitsche interface against strong Dirichlet conditions.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

#include "fsi/common/gmsh_reader.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"
#include "fsi/fluid/p2p1_element.hpp"
#include "fsi/fluid/taylor_hood_solver.hpp"

namespace {

using namespace fsi::fluid;

TEST(P2Element, ShapeFunctionsInterpolateAndSumToOne) {
  Eigen::Matrix<double, 6, 1> N;
  Eigen::Matrix<double, 6, 2> dN;
  const double pts[6][2] = {{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}};
  for (int k = 0; k < 6; ++k) {
    p2_shape(pts[k][0], pts[k][1], N, dN);
    for (int j = 0; j < 6; ++j) EXPECT_NEAR(N(j), j == k ? 1.0 : 0.0, 1e-15);
  }
  p2_shape(0.2, 0.3, N, dN);
  EXPECT_NEAR(N.sum(), 1.0, 1e-15);
  EXPECT_NEAR(dN.col(0).sum(), 0.0, 1e-14);
  EXPECT_NEAR(dN.col(1).sum(), 0.0, 1e-14);
  // A quadratic field is reproduced exactly: f = x^2 + x y at the nodes.
  double f = 0;
  for (int j = 0; j < 6; ++j) f += N(j) * (pts[j][0] * pts[j][0] + pts[j][0] * pts[j][1]);
  EXPECT_NEAR(f, 0.2 * 0.2 + 0.2 * 0.3, 1e-15);
}

struct Kovasznay {
  double re = 40;
  double lambda = re / 2 - std::sqrt(re * re / 4 + 4 * M_PI * M_PI);
  Eigen::Vector2d velocity(const Eigen::Vector2d& x) const {
    const double e = std::exp(lambda * x.x());
    return {1 - e * std::cos(2 * M_PI * x.y()), lambda / (2 * M_PI) * e * std::sin(2 * M_PI * x.y())};
  }
  double pressure(const Eigen::Vector2d& x) const { return -0.5 * std::exp(2 * lambda * x.x()); }
};

// L2 errors of velocity and (mean-corrected) pressure over the current configuration.
std::pair<double, double> l2_errors(const TaylorHoodSolver& s, const Kovasznay& k) {
  const auto& mesh = s.mesh();
  const auto& X = s.positions();
  const auto& U = s.solution();
  const int n = mesh.node_count();
  // 7-point degree-5 rule (barycentric L1, L2, weight).
  const double a1 = 0.059715871789770, b1 = 0.470142064105115, w1 = 0.132394152788506;
  const double a2 = 0.797426985353087, b2 = 0.101286507323456, w2 = 0.125939180544827;
  const double rule[7][3] = {
      {1.0 / 3, 1.0 / 3, 0.225}, {b1, b1, w1}, {a1, b1, w1}, {b1, a1, w1}, {b2, b2, w2}, {a2, b2, w2}, {b2, a2, w2}};
  double ev = 0, ep = 0, mean = 0, area = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int e = 0; e < mesh.triangle_count(); ++e) {
      const auto nodes = mesh.element_nodes6(e);
      Eigen::Matrix<double, 6, 2> x;
      for (int a = 0; a < 6; ++a) x.row(a) = X.row(nodes(a));
      for (const auto& q : rule) {
        Eigen::Matrix<double, 6, 1> N;
        Eigen::Matrix<double, 6, 2> dN;
        p2_shape(q[0], q[1], N, dN);
        const double w = 0.5 * q[2] * (x.transpose() * dN).determinant();
        const Eigen::Vector2d xq = x.transpose() * N;
        Eigen::Vector2d uh = Eigen::Vector2d::Zero();
        for (int a = 0; a < 6; ++a) uh += N(a) * U.segment<2>(2 * nodes(a));
        const double L[3] = {1 - q[0] - q[1], q[0], q[1]};
        double ph = 0;
        for (int a = 0; a < 3; ++a) ph += L[a] * U(2 * n + nodes(a));
        const double dp = ph - k.pressure(xq);
        if (pass == 0) {
          mean += w * dp;
          area += w;
        } else {
          ev += w * (uh - k.velocity(xq)).squaredNorm();
          ep += w * std::pow(dp - mean, 2);
        }
      }
    }
    if (pass == 0) mean /= area;
  }
  return {std::sqrt(ev), std::sqrt(ep)};
}

FlowParameters kovasznay_parameters(const Kovasznay& k) {
  FlowParameters p;
  p.density = 1;
  p.viscosity = 1 / k.re;
  p.scheme = TimeScheme::Steady;
  p.newton = true;
  p.max_iterations = 20;
  p.tolerance = 1e-12;
  p.stabilisation.supg = false;
  p.stabilisation.pspg = false;
  return p;
}

struct KovasznayResult {
  double ev, ep;
  int iterations;
};

KovasznayResult kovasznay_steady(int nx) {
  const Kovasznay k;
  TaylorHoodSolver s(FluidMesh::rectangle(-0.5, 1.0, -0.5, 1.5, nx, nx * 4 / 3), kovasznay_parameters(k));
  auto exact = [&k](const Eigen::Vector2d& x, double) { return k.velocity(x); };
  for (const char* g : {"left", "right", "bottom", "top"}) s.add_dirichlet(g, exact);
  s.set_pressure_reference({-0.5, -0.5}, [&k](double) { return k.pressure({-0.5, -0.5}); });
  const auto report = s.solve(1.0, 1.0, s.mesh().nodes, {});
  EXPECT_LT(report.change, 1e-11) << "Newton did not converge on " << nx;
  const auto [ev, ep] = l2_errors(s, k);
  return {ev, ep, report.iterations};
}

TEST(TaylorHood, KovasznayConvergesAtThirdOrderInVelocityAndSecondInPressure) {
  const int sizes[3] = {6, 12, 24};
  KovasznayResult r[3];
  for (int i = 0; i < 3; ++i) r[i] = kovasznay_steady(sizes[i]);
  const double rate_v = std::log(r[1].ev / r[2].ev) / std::log(2.0);
  const double rate_p = std::log(r[1].ep / r[2].ep) / std::log(2.0);
  std::printf(
      "Kovasznay Re 40, P2/P1 Newton: velocity L2 %.3e %.3e %.3e (rate %.2f); pressure %.3e %.3e %.3e "
      "(rate %.2f); Newton solves %d %d %d\n",
      r[0].ev, r[1].ev, r[2].ev, rate_v, r[0].ep, r[1].ep, r[2].ep, rate_p, r[0].iterations, r[1].iterations,
      r[2].iterations);
  EXPECT_GT(rate_v, 2.8);
  EXPECT_GT(rate_p, 1.8);
  // Newton from the Stokes solution converges quadratically: a handful of solves to 1e-12.
  for (const auto& x : r) EXPECT_LE(x.iterations, 7);
}

// The same steady flow on a mesh whose interior moves (x = X + A sin(pi t / T) b(X), b = 0
// on the boundary), time-stepped with the ALE BDF2 semi-implicit scheme from the exact state:
// the solution must stay the Eulerian steady one up to the spatial error (rates 3 / 2).
KovasznayResult kovasznay_moving(int nx) {
  const Kovasznay k;
  auto p = kovasznay_parameters(k);
  p.scheme = TimeScheme::BDF2;
  p.newton = false;
  p.max_iterations = 1;
  TaylorHoodSolver s(FluidMesh::rectangle(-0.5, 1.0, -0.5, 1.5, nx, nx * 4 / 3), p);
  auto exact = [&k](const Eigen::Vector2d& x, double) { return k.velocity(x); };
  for (const char* g : {"left", "right", "bottom", "top"}) s.add_dirichlet(g, exact);
  s.set_pressure_reference({-0.5, -0.5}, [&k](double) { return k.pressure({-0.5, -0.5}); });
  const Eigen::MatrixX2d X0 = s.mesh().nodes;
  Eigen::MatrixX2d u0(X0.rows(), 2);
  for (Eigen::Index i = 0; i < X0.rows(); ++i) u0.row(i) = k.velocity(X0.row(i).transpose()).transpose();
  s.set_initial_velocity(u0);
  auto positions = [&](double t) {
    Eigen::MatrixX2d X = X0;
    for (Eigen::Index i = 0; i < X0.rows(); ++i) {
      const double bx = (X0(i, 0) + 0.5) * (1.0 - X0(i, 0)), by = (X0(i, 1) + 0.5) * (1.5 - X0(i, 1));
      const double bump = 4 * bx * by;  // 0 on the boundary, O(1) inside
      X(i, 0) += 0.03 * std::sin(M_PI * t) * bump;
      X(i, 1) += 0.02 * std::sin(M_PI * t) * bump;
    }
    return X;
  };
  const double dt = 0.02;
  int solves = 0;
  for (int step = 1; step <= 25; ++step) {
    solves += s.solve(step * dt, dt, positions(step * dt), {}).iterations;
    s.accept();
  }
  const auto [ev, ep] = l2_errors(s, k);
  return {ev, ep, solves};
}

TEST(TaylorHood, KovasznayOnAMovingMeshKeepsTheSpatialRates) {
  const int sizes[3] = {6, 12, 24};
  KovasznayResult r[3];
  for (int i = 0; i < 3; ++i) r[i] = kovasznay_moving(sizes[i]);
  const double rate_v = std::log(r[1].ev / r[2].ev) / std::log(2.0);
  const double rate_p = std::log(r[1].ep / r[2].ep) / std::log(2.0);
  std::printf(
      "Kovasznay Re 40 on a moving mesh (ALE BDF2, 25 steps): velocity L2 %.3e %.3e %.3e (rate %.2f); pressure "
      "%.3e %.3e %.3e (rate %.2f)\n",
      r[0].ev, r[1].ev, r[2].ev, rate_v, r[0].ep, r[1].ep, r[2].ep, rate_p);
  EXPECT_GT(rate_v, 2.7);
  EXPECT_GT(rate_p, 1.7);
}

// Nitsche interface with P2 traces: a rotating cylinder in the DFG channel (isoparametric
// mesh), its wall velocity imposed strongly and through Nitsche with gamma_N2 = +1 / -1.
const Eigen::Vector2d kCentre(0.2, 0.2);
constexpr double kOmega = 4.0;  // rad/s: wall speed 0.2, comparable to U_bar

Eigen::Vector2d rotation(const Eigen::Vector2d& x) {
  const Eigen::Vector2d r = x - kCentre;
  return kOmega * Eigen::Vector2d(-r.y(), r.x());
}

TaylorHoodSolver rotating_cylinder(const FluidMesh& mesh, bool nitsche, double penalty, double symmetry) {
  FlowParameters p;
  p.density = 1;
  p.viscosity = 1e-3;
  p.scheme = TimeScheme::Steady;
  p.newton = true;
  p.max_iterations = 30;
  p.tolerance = 1e-10;
  p.nitsche_penalty = penalty;
  p.nitsche_symmetry = symmetry;
  p.stabilisation.supg = false;
  TaylorHoodSolver s(mesh, p);
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

TEST(TaylorHood, NitscheRotatingCylinderMatchesStrongDirichletForBothSymmetries) {
  const auto msh = mesh_geo(FSI_FLUID_SOURCE_DIR "/configs/meshes/dfg_cylinder.geo", {{"h", 0.06}, {"hc", 0.008}},
                            std::filesystem::temp_directory_path() / "fsi_fluid_test_meshes", 2);
  const auto mesh = FluidMesh::from_gmsh(fsi::read_gmsh(msh));
  ASSERT_TRUE(mesh.quadratic());
  // Isoparametric: every cylinder midpoint lies on the circle (gmsh -order 2).
  const auto& mids = mesh.boundary_midpoints.at("cylinder");
  for (Eigen::Index i = 0; i < mids.size(); ++i)
    ASSERT_NEAR((mesh.nodes.row(mids(i)).transpose() - kCentre).norm(), 0.05, 1e-9);
  auto strong = rotating_cylinder(mesh, false, 0, -1);
  ASSERT_LT(strong.solve(1, 1, mesh.nodes, {}).change, 1e-9);
  const Eigen::Vector2d f_strong = strong.force({"cylinder"});
  const double scale = 2 / (0.2 * 0.2 * 0.1);
  std::printf("P2/P1 strong:   C_D %.5f  C_L %.5f\n", scale * f_strong.x(), scale * f_strong.y());
  EXPECT_GT(std::abs(f_strong.y()), 0.05 * f_strong.x()) << "rotation should produce a clear Magnus lift";
  for (double symmetry : {+1.0, -1.0}) {
    auto weak = rotating_cylinder(mesh, true, 100.0, symmetry);
    Eigen::VectorXd vs(2 * static_cast<Eigen::Index>(weak.interface_nodes().size()));
    for (std::size_t i = 0; i < weak.interface_nodes().size(); ++i)
      vs.segment<2>(2 * static_cast<Eigen::Index>(i)) = rotation(mesh.nodes.row(weak.interface_nodes()[i]).transpose());
    ASSERT_LT(weak.solve(1, 1, mesh.nodes, vs).change, 1e-9);
    const Eigen::Vector2d f = weak.force({"cylinder"});
    // F* = f_sigma - gamma_N1 (f_v - int N^T v_s) is the consistent reaction: its sum is minus the force.
    const Eigen::VectorXd fs = weak.interface_traction();
    Eigen::Vector2d total_sigma = Eigen::Vector2d::Zero();
    for (Eigen::Index i = 0; i < fs.size() / 2; ++i) total_sigma += fs.segment<2>(2 * i);
    std::printf("P2/P1 gamma_N2 %+g gamma_N1 100: C_D %.5f  C_L %.5f (sum of f_sigma: %.5f %.5f)\n", symmetry,
                scale * f.x(), scale * f.y(), -scale * total_sigma.x(), -scale * total_sigma.y());
    EXPECT_NEAR(f.x(), f_strong.x(), 0.005 * f_strong.x()) << "gamma_N2 " << symmetry;
    EXPECT_NEAR(f.y(), f_strong.y(), 0.02 * std::abs(f_strong.y())) << "gamma_N2 " << symmetry;
    EXPECT_NEAR(-total_sigma.x(), f.x(), 0.02 * f.x());
    // The interface nodes are the vertices and the midpoints of the cylinder edges.
    EXPECT_EQ(weak.interface_nodes().size(), 2 * mesh.boundary("cylinder").rows());
    EXPECT_EQ(weak.interface_segments().rows(), 2 * mesh.boundary("cylinder").rows());
  }
}

TEST(TaylorHood, SolidBodyTranslationThroughNitscheIsExact) {
  // Every wall of a box moves with the same velocity (Nitsche on all sides, pressure pinned):
  // u = const, p = 0 is reproduced to round-off for both gamma_N2.
  const auto mesh = FluidMesh::rectangle(0, 1, 0, 1, 6, 6);
  for (double symmetry : {+1.0, -1.0}) {
    FlowParameters p;
    p.viscosity = 0.01;
    p.scheme = TimeScheme::BDF1;
    p.nitsche_penalty = 10;
    p.nitsche_symmetry = symmetry;
    p.stabilisation.supg = false;
    TaylorHoodSolver s(mesh, p);
    s.set_interface({"left", "right", "bottom", "top"});
    s.set_pressure_reference({0.5, 0.5}, [](double) { return 0.0; });
    Eigen::MatrixX2d initial(s.mesh().node_count(), 2);
    initial.col(0).setConstant(0.3);
    initial.col(1).setConstant(-0.2);
    s.set_initial_velocity(initial);
    Eigen::VectorXd vs(2 * static_cast<Eigen::Index>(s.interface_nodes().size()));
    for (Eigen::Index i = 0; i < vs.size() / 2; ++i) vs.segment<2>(2 * i) << 0.3, -0.2;
    s.solve(0.1, 0.1, s.mesh().nodes, vs);
    const auto v = s.velocity();
    EXPECT_NEAR((v.col(0).array() - 0.3).abs().maxCoeff(), 0.0, 1e-10);
    EXPECT_NEAR((v.col(1).array() + 0.2).abs().maxCoeff(), 0.0, 1e-10);
    EXPECT_NEAR(s.pressure().cwiseAbs().maxCoeff(), 0.0, 1e-10);
    // f_v = int N^T v_f sums to v times the perimeter (4).
    const Eigen::VectorXd fv = s.interface_velocity_integral();
    double sx = 0, sy = 0;
    for (Eigen::Index i = 0; i < fv.size() / 2; ++i) {
      sx += fv(2 * i);
      sy += fv(2 * i + 1);
    }
    EXPECT_NEAR(sx, 0.3 * 4, 1e-12);
    EXPECT_NEAR(sy, -0.2 * 4, 1e-12);
  }
}

TEST(TaylorHood, PressureInletDrivesExactPoiseuille) {
  // fluid.pressures in 2D: the inlet x = 0 a normal traction -p_in n, the outlet do-nothing,
  // no-slip walls: u = p_in y (H - y) / (2 mu L), p = p_in (1 - x / L), exact in P2/P1.
  const double L = 2, H = 1, mu = 0.1, p_in = 0.6;
  FlowParameters p;
  p.viscosity = mu;
  p.scheme = TimeScheme::Steady;
  p.newton = true;
  p.max_iterations = 8;
  p.tolerance = 1e-12;
  p.stabilisation.supg = false;
  p.reuse_factorisation = false;
  TaylorHoodSolver s(FluidMesh::rectangle(0, L, 0, H, 6, 3), p);
  const auto zero = [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero().eval(); };
  s.add_dirichlet("bottom", zero);
  s.add_dirichlet("top", zero);
  s.add_pressure("left", [&](double) { return p_in; });
  s.solve(1, 1, s.mesh().nodes, {});
  const auto v = s.velocity();
  double err = 0;
  for (int i = 0; i < s.mesh().node_count(); ++i) {
    const double y = s.mesh().nodes(i, 1);
    err = std::max(err, (v.row(i).transpose() - Eigen::Vector2d(p_in * y * (H - y) / (2 * mu * L), 0)).norm());
  }
  EXPECT_LT(err, 1e-10);
  EXPECT_NEAR(s.pressure_at({0.3, 0.4}), p_in * (1 - 0.3 / L), 1e-10);
}

TEST(TaylorHood, BadlyCurvedElementIsReportedWithTimeAndPlace) {
  TaylorHoodSolver s(FluidMesh::rectangle(0, 1, 0, 1, 4, 4), FlowParameters{});
  s.add_dirichlet("bottom", [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); });
  Eigen::MatrixX2d x = s.mesh().nodes;
  // Push the midpoint of element 5's first edge far past the opposite vertex: the quadratic
  // map folds (det J < 0 inside) although the vertices are untouched.
  const int mid = s.mesh().edge_nodes(5, 0);
  const int opposite = s.mesh().triangles(5, 2);
  x.row(mid) += 2.0 * (x.row(opposite) - x.row(mid));
  try {
    s.solve(0.25, 0.25, x, {});
    FAIL() << "expected a SolverError";
  } catch (const fsi::SolverError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("t = 0.25"), std::string::npos) << what;
    EXPECT_NE(what.find("curved"), std::string::npos) << what;
    EXPECT_NE(what.find("near ("), std::string::npos) << what;
  }
}

TEST(FluidMesh, QuadraticMeshHelpersAreConsistent) {
  const auto linear = FluidMesh::rectangle(0, 2, 0, 1, 4, 2);
  const auto quad = linear.quadratic_from_linear();
  ASSERT_TRUE(quad.quadratic());
  EXPECT_EQ(quad.vertices(), linear.node_count());
  // Euler: edges = vertices + triangles - 1 for a disc; one midpoint per edge.
  EXPECT_EQ(quad.node_count(), linear.node_count() + (linear.node_count() + linear.triangle_count() - 1));
  for (int e = 0; e < quad.triangle_count(); ++e)
    for (int k = 0; k < 3; ++k) {
      const Eigen::RowVector2d m =
          0.5 * (quad.nodes.row(quad.triangles(e, k)) + quad.nodes.row(quad.triangles(e, (k + 1) % 3)));
      EXPECT_NEAR((quad.nodes.row(quad.edge_nodes(e, k)) - m).norm(), 0.0, 1e-15);
    }
  EXPECT_EQ(quad.boundary_nodes({"bottom"}).size(), 9u);  // 5 vertices + 4 midpoints
  const auto refined = quad.linear_refinement();
  EXPECT_EQ(refined.triangle_count(), 4 * quad.triangle_count());
  EXPECT_EQ(refined.boundary("bottom").rows(), 8);
  double area = 0;
  for (int e = 0; e < refined.triangle_count(); ++e) {
    Eigen::Matrix<double, 3, 2> x;
    for (int k = 0; k < 3; ++k) x.row(k) = refined.nodes.row(refined.triangles(e, k));
    const double a = 0.5 * ((x(1, 0) - x(0, 0)) * (x(2, 1) - x(0, 1)) - (x(1, 1) - x(0, 1)) * (x(2, 0) - x(0, 0)));
    EXPECT_GT(a, 0.0);
    area += a;
  }
  EXPECT_NEAR(area, 2.0, 1e-12);
}

}  // namespace
