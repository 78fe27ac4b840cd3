#include "fsi/fluid/p1_element.hpp"

#include <cmath>

namespace fsi::fluid {

TriangleGeometry triangle_geometry(const Eigen::Matrix<double, 3, 2>& x) {
  TriangleGeometry g;
  const double x10 = x(1, 0) - x(0, 0), y10 = x(1, 1) - x(0, 1);
  const double x20 = x(2, 0) - x(0, 0), y20 = x(2, 1) - x(0, 1);
  const double det = x10 * y20 - x20 * y10;
  g.area = 0.5 * det;
  if (det == 0) return g;
  // grad N1 = ( y20, -x20)/det, grad N2 = (-y10, x10)/det, grad N0 = -(grad N1 + grad N2)
  g.grad(1, 0) = y20 / det;
  g.grad(1, 1) = -x20 / det;
  g.grad(2, 0) = -y10 / det;
  g.grad(2, 1) = x10 / det;
  g.grad(0, 0) = -g.grad(1, 0) - g.grad(2, 0);
  g.grad(0, 1) = -g.grad(1, 1) - g.grad(2, 1);
  return g;
}

void assemble_element(const ElementInput& in, const StabilisationParameters& stab, ElementOutput& out) {
  out.matrix.setZero();
  out.rhs.setZero();
  const TriangleGeometry g = triangle_geometry(in.x);
  const double area = g.area;
  const auto& dN = g.grad;
  const double rho = in.density, mu = in.viscosity, nu = mu / rho;

  // Stabilisation parameters from the centroid advection velocity.
  const Eigen::RowVector2d a_c = in.advection.colwise().mean();
  const double a_norm = a_c.norm();
  const double h_size = std::sqrt(4.0 * area / std::sqrt(3.0));  // side of the equilateral triangle of equal area
  double h_adv = h_size;
  if (a_norm > 1e-14 * (1.0 + nu / h_size)) {
    const double s = (dN * a_c.transpose()).cwiseAbs().sum();
    if (s > 0) h_adv = 2.0 * a_norm / s;
  }
  double inv_tau2 =
      std::pow(2.0 * a_norm / h_adv, 2) + std::pow(stab.viscous_constant * 4.0 * nu / (h_size * h_size), 2);
  if (stab.transient_tau && in.dt > 0) inv_tau2 += std::pow(2.0 / in.dt, 2);
  const double tau_m = 1.0 / std::sqrt(inv_tau2);
  const double tau_c = stab.lsic_scale * h_size * h_size / (8.0 * tau_m);
  out.tau_m = tau_m;
  out.tau_c = tau_c;
  const double tau_supg = stab.supg ? tau_m : 0.0;
  const double tau_pspg = stab.pspg ? tau_m : 0.0;

  // Three-point rule (exact for quadratics): barycentric (2/3, 1/6, 1/6) and permutations.
  static const double kN[3][3] = {
      {2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}};
  const double w = area / 3.0;
  // Newton: the Galerkin convection's derivative (du . grad) u_k, grad u_k constant in P1.
  const Eigen::Matrix2d Gu = in.newton ? Eigen::Matrix2d(in.velocity.transpose() * dN) : Eigen::Matrix2d::Zero();
  for (int q = 0; q < 3; ++q) {
    const Eigen::Vector3d N(kN[q][0], kN[q][1], kN[q][2]);
    const Eigen::RowVector2d a = N.transpose() * in.advection;
    const Eigen::RowVector2d hist = N.transpose() * in.history;
    const Eigen::RowVector2d f = N.transpose() * in.force;
    const Eigen::Vector3d adv = dN * a.transpose();  // a . grad N_k
    // rhs of the residual: f - rho history (per component); the stabilisation terms also get the
    // known viscous part of the strong residual (zero unless reconstructed).
    const Eigen::RowVector2d src = f - rho * hist;
    const Eigen::RowVector2d src_stab = src + in.viscous;
    for (int i = 0; i < 3; ++i) {
      for (int c = 0; c < 2; ++c) {
        out.rhs(3 * i + c) += w * (N(i) * src(c) + tau_supg * adv(i) * src_stab(c));
      }
      if (in.newton) {
        const Eigen::RowVector2d uk = N.transpose() * in.velocity;
        for (int c = 0; c < 2; ++c)
          out.rhs(3 * i + c) += w * N(i) * rho * uk.dot(Gu.row(c));  // (w, rho (u_k . grad) u_k)
      }
      out.rhs(3 * i + 2) += w * (tau_pspg / rho) * dN.row(i).dot(src_stab);
      for (int j = 0; j < 3; ++j) {
        const double transport = rho * (in.alpha0_dt * N(j) + adv(j));  // rho(alpha0/dt N_j + a.grad N_j)
        const double vel = w * (N(i) * transport + mu * dN.row(i).dot(dN.row(j)) + tau_supg * adv(i) * transport);
        for (int c = 0; c < 2; ++c) {
          out.matrix(3 * i + c, 3 * j + c) += vel;
          // pressure in momentum: -(div w, p) + SUPG (a.grad w, grad p)
          out.matrix(3 * i + c, 3 * j + 2) += w * (-dN(i, c) * N(j) + tau_supg * adv(i) * dN(j, c));
          // continuity: (q, div u) + PSPG (grad q / rho, rho(...))
          out.matrix(3 * i + 2, 3 * j + c) += w * (N(i) * dN(j, c) + (tau_pspg / rho) * dN(i, c) * transport);
        }
        out.matrix(3 * i + 2, 3 * j + 2) += w * (tau_pspg / rho) * dN.row(i).dot(dN.row(j));
        if (in.newton)
          for (int c = 0; c < 2; ++c)
            for (int d = 0; d < 2; ++d) out.matrix(3 * i + c, 3 * j + d) += w * rho * N(i) * N(j) * Gu(c, d);
      }
    }
  }
  // LSIC / grad-div (constant over the element).
  if (tau_c > 0)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int c = 0; c < 2; ++c)
          for (int d = 0; d < 2; ++d) out.matrix(3 * i + c, 3 * j + d) += area * tau_c * rho * dN(i, c) * dN(j, d);
}

}  // namespace fsi::fluid
