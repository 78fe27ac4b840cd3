// Kernel-level checks of the P1/P1 stabilised Navier-Stokes solver: element matrices,
// Poiseuille flow, the Kovasznay solution with its observed convergence rate.
#include <gtest/gtest.h>

#include <cmath>

#include "fsi/fluid/navier_stokes_solver.hpp"

namespace {

using fsi::fluid::FlowParameters;
using fsi::fluid::FluidMesh;
using fsi::fluid::NavierStokesSolver;
using fsi::fluid::TimeScheme;

TEST(P1Element, GeometryAndGradients) {
  Eigen::Matrix<double, 3, 2> x;
  x << 0, 0, 2, 0, 0, 1;
  const auto g = fsi::fluid::triangle_geometry(x);
  EXPECT_DOUBLE_EQ(g.area, 1.0);
  EXPECT_NEAR(g.grad(1, 0), 0.5, 1e-15);
  EXPECT_NEAR(g.grad(2, 1), 1.0, 1e-15);
  EXPECT_NEAR(g.grad.col(0).sum(), 0.0, 1e-15);
}

TEST(P1Element, RowsAnnihilateConstantsAndLinearFieldsAreConsistent) {
  // For a steady Stokes-like element with no advection: a constant velocity produces no
  // viscous force; a linear pressure field gives grad p, and the Galerkin pressure block
  // sums to -int div w p.
  fsi::fluid::ElementInput in;
  in.x << 0, 0, 1, 0.1, 0.2, 0.9;
  in.advection.setZero();
  in.history.setZero();
  in.force.setZero();
  in.density = 1.0;
  in.viscosity = 0.1;
  fsi::fluid::StabilisationParameters stab;
  fsi::fluid::ElementOutput out;
  fsi::fluid::assemble_element(in, stab, out);
  Eigen::Matrix<double, 9, 1> constant_velocity;
  constant_velocity << 1, 2, 0, 1, 2, 0, 1, 2, 0;
  const Eigen::Matrix<double, 9, 1> r = out.matrix * constant_velocity;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(r(3 * i), 0.0, 1e-12);  // no viscous or LSIC force
    EXPECT_NEAR(r(3 * i + 1), 0.0, 1e-12);
    EXPECT_NEAR(r(3 * i + 2), 0.0, 1e-12);  // divergence-free, no PSPG residual
  }
  // A uniform pressure gives zero momentum force after summing over the element's nodes
  // (-int div(sum_i w_i) p = 0) ... and the PSPG pressure Laplacian annihilates constants.
  Eigen::Matrix<double, 9, 1> constant_pressure;
  constant_pressure << 0, 0, 1, 0, 0, 1, 0, 0, 1;
  const Eigen::Matrix<double, 9, 1> rp = out.matrix * constant_pressure;
  EXPECT_NEAR(rp(0) + rp(3) + rp(6), 0.0, 1e-12);
  EXPECT_NEAR(rp(2) + rp(5) + rp(8), 0.0, 1e-12);
  // Symmetric viscous block for zero advection and no time term.
  Eigen::Matrix3d visc;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) visc(i, j) = out.matrix(3 * i, 3 * j);
  EXPECT_NEAR((visc - visc.transpose()).norm(), 0.0, 1e-12);
  EXPECT_GT(out.tau_m, 0.0);
}

// Poiseuille flow in [0, 2] x [0, 1]: parabolic inflow, no-slip walls, do-nothing outlet.
TEST(NavierStokesSolver, PoiseuilleFlowIsReproduced) {
  auto mesh = FluidMesh::rectangle(0, 2, 0, 1, 32, 16);
  FlowParameters params;
  params.density = 1;
  params.viscosity = 0.1;
  params.scheme = TimeScheme::Steady;
  params.max_iterations = 30;
  params.tolerance = 1e-10;
  NavierStokesSolver solver(mesh, params);
  auto profile = [](const Eigen::Vector2d& x, double) { return Eigen::Vector2d(4 * x.y() * (1 - x.y()), 0); };
  solver.add_dirichlet("left", profile);
  solver.add_dirichlet("bottom", [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); });
  solver.add_dirichlet("top", [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); });
  const auto report = solver.solve(1.0, 1.0, mesh.nodes, {});
  EXPECT_LT(report.change, 1e-8);
  const auto v = solver.velocity();
  double err = 0;
  for (int i = 0; i < mesh.node_count(); ++i)
    err = std::max(err, (v.row(i).transpose() - profile(mesh.nodes.row(i), 0)).norm());
  EXPECT_LT(err, 1e-2);  // P1 interpolation of the parabola: h^2/8 |u''| = 4e-3
  // dp/dx = -8 mu (u_max 1, half-height 0.5): p(0.5) - p(1.5) = 0.8
  const double dp = solver.pressure_at({0.5, 0.5}) - solver.pressure_at({1.5, 0.5});
  EXPECT_NEAR(dp, 0.8, 0.8 * 0.01);
  // Wall shear: each wall carries mu du/dn * length = 0.1 * 4 * 2 = 0.8 in +x. The inlet corner
  // node also carries the inlet's reaction, so sum the bottom wall without it: 0.8 - tau h / 2.
  double shear = 0;
  for (int node : mesh.boundary_nodes({"bottom"}))
    if (mesh.nodes(node, 0) > 1e-12) shear -= solver.reaction()(3 * node);
  EXPECT_NEAR(shear, 0.8 - 0.4 * (2.0 / 32) / 2, 0.8 * 0.01);
  // Global balance: the do-nothing outlet carries no pseudo-traction and the momentum flux
  // in equals the flux out, so the Dirichlet boundaries take (almost) no net force.
  EXPECT_NEAR(solver.force({"left", "bottom", "top"}).x(), 0.0, 2e-3);
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

// L2 errors (velocity, pressure) on an n x (4n/3) mesh of [-0.5, 1] x [-0.5, 1.5].
std::pair<double, double> kovasznay_errors(int nx, bool viscous_residual = false) {
  const Kovasznay k;
  auto mesh = FluidMesh::rectangle(-0.5, 1.0, -0.5, 1.5, nx, nx * 4 / 3);
  FlowParameters params;
  params.density = 1;
  params.viscosity = 1 / k.re;
  params.scheme = TimeScheme::Steady;
  params.max_iterations = 60;
  params.tolerance = 1e-11;
  params.stabilisation.viscous_residual = viscous_residual;
  NavierStokesSolver solver(mesh, params);
  auto exact = [&k](const Eigen::Vector2d& x, double) { return k.velocity(x); };
  for (const char* g : {"left", "right", "bottom", "top"}) solver.add_dirichlet(g, exact);
  solver.set_pressure_reference({-0.5, -0.5}, [&k](double) { return k.pressure({-0.5, -0.5}); });
  const auto report = solver.solve(1.0, 1.0, mesh.nodes, {});
  EXPECT_LT(report.change, 1e-9) << "Picard did not converge on " << nx;
  // The discrete pressure is fixed at one node; compare after removing the mean difference.
  const auto& U = solver.solution();
  static const double kN[3][3] = {
      {2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}};
  double ev = 0, ep = 0, mean_diff = 0, area_sum = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (int e = 0; e < mesh.triangle_count(); ++e) {
      Eigen::Matrix<double, 3, 2> x;
      for (int a = 0; a < 3; ++a) x.row(a) = mesh.nodes.row(mesh.triangles(e, a));
      const double area = fsi::fluid::triangle_geometry(x).area;
      for (int q = 0; q < 3; ++q) {
        Eigen::Vector2d xq = Eigen::Vector2d::Zero(), uh = Eigen::Vector2d::Zero();
        double ph = 0;
        for (int a = 0; a < 3; ++a) {
          const int node = mesh.triangles(e, a);
          xq += kN[q][a] * x.row(a).transpose();
          uh += kN[q][a] * U.segment<2>(3 * node);
          ph += kN[q][a] * U(3 * node + 2);
        }
        const double dpq = ph - k.pressure(xq);
        if (pass == 0) {
          mean_diff += area / 3 * dpq;
          area_sum += area / 3;
        } else {
          ev += area / 3 * (uh - k.velocity(xq)).squaredNorm();
          ep += area / 3 * std::pow(dpq - mean_diff, 2);
        }
      }
      if (pass == 0 && e == mesh.triangle_count() - 1) mean_diff /= area_sum;
    }
  return {std::sqrt(ev), std::sqrt(ep)};
}

TEST(NavierStokesSolver, KovasznayConvergesAtSecondOrderInVelocity) {
  const int sizes[3] = {12, 24, 48};
  double ev[3], ep[3];
  for (int k = 0; k < 3; ++k) std::tie(ev[k], ep[k]) = kovasznay_errors(sizes[k]);
  const double rate_v = std::log(ev[1] / ev[2]) / std::log(2.0);
  const double rate_p = std::log(ep[1] / ep[2]) / std::log(2.0);
  std::printf("Kovasznay Re 40: velocity L2 errors %.3e %.3e %.3e (rate %.2f); pressure %.3e %.3e %.3e (rate %.2f)\n",
              ev[0], ev[1], ev[2], rate_v, ep[0], ep[1], ep[2], rate_p);
  EXPECT_GT(rate_v, 1.8);
  EXPECT_GT(rate_p, 1.2);
  EXPECT_LT(ev[2], 1e-2);
}

// The reconstructed viscous residual (L2-projected gradients) makes SUPG/PSPG consistent for
// P1: the same rates, smaller errors, most of all in the pressure (Jansen et al. 1999).
TEST(NavierStokesSolver, KovasznayWithReconstructedViscousResidual) {
  const int sizes[3] = {12, 24, 48};
  double ev[3], ep[3], ev0[3], ep0[3];
  for (int k = 0; k < 3; ++k) {
    std::tie(ev[k], ep[k]) = kovasznay_errors(sizes[k], true);
    std::tie(ev0[k], ep0[k]) = kovasznay_errors(sizes[k], false);
  }
  const double rate_v = std::log(ev[1] / ev[2]) / std::log(2.0);
  const double rate_p = std::log(ep[1] / ep[2]) / std::log(2.0);
  std::printf(
      "Kovasznay Re 40, viscous residual: velocity L2 errors %.3e %.3e %.3e (rate %.2f); pressure %.3e %.3e "
      "%.3e (rate %.2f); pressure error ratio to the plain residual %.3f %.3f %.3f\n",
      ev[0], ev[1], ev[2], rate_v, ep[0], ep[1], ep[2], rate_p, ep[0] / ep0[0], ep[1] / ep0[1], ep[2] / ep0[2]);
  EXPECT_GT(rate_v, 1.8);
  EXPECT_GT(rate_p, 1.2);
  for (int k = 0; k < 3; ++k) EXPECT_LT(ep[k], ep0[k]) << "mesh " << sizes[k];
}

}  // namespace
