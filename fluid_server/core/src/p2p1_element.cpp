#include "fsi/fluid/p2p1_element.hpp"

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <limits>

namespace fsi::fluid {
namespace {

// 7-point Dunavant rule, exact for degree 5 (barycentric L1, L2; weights sum to 1).
struct QuadraturePoint {
  double xi, eta, weight;
};
constexpr double a1 = 0.059715871789770, b1 = 0.470142064105115, w1 = 0.132394152788506;
constexpr double a2 = 0.797426985353087, b2 = 0.101286507323456, w2 = 0.125939180544827;
constexpr std::array<QuadraturePoint, 7> kRule = {
    {{1.0 / 3, 1.0 / 3, 0.225}, {b1, b1, w1}, {a1, b1, w1}, {b1, a1, w1}, {b2, b2, w2}, {a2, b2, w2}, {b2, a2, w2}}};

// Reference Hessians of the P2 shape functions (constant): d2N/dxi_a dxi_b.
std::array<Eigen::Matrix2d, 6> reference_hessians() {
  // L0 = 1 - xi - eta, L1 = xi, L2 = eta; grad L0 = (-1, -1), grad L1 = (1, 0), grad L2 = (0, 1).
  const Eigen::Vector2d g0(-1, -1), g1(1, 0), g2(0, 1);
  std::array<Eigen::Matrix2d, 6> h;
  h[0] = 4 * g0 * g0.transpose();
  h[1] = 4 * g1 * g1.transpose();
  h[2] = 4 * g2 * g2.transpose();
  h[3] = 4 * (g0 * g1.transpose() + g1 * g0.transpose());
  h[4] = 4 * (g1 * g2.transpose() + g2 * g1.transpose());
  h[5] = 4 * (g2 * g0.transpose() + g0 * g2.transpose());
  return h;
}

}  // namespace

void p2_shape(double xi, double eta, Eigen::Matrix<double, 6, 1>& N, Eigen::Matrix<double, 6, 2>& dN) {
  const double L0 = 1 - xi - eta, L1 = xi, L2 = eta;
  N << L0 * (2 * L0 - 1), L1 * (2 * L1 - 1), L2 * (2 * L2 - 1), 4 * L0 * L1, 4 * L1 * L2, 4 * L2 * L0;
  const double d0 = 4 * L0 - 1;
  dN.row(0) << -d0, -d0;
  dN.row(1) << 4 * L1 - 1, 0;
  dN.row(2) << 0, 4 * L2 - 1;
  dN.row(3) << 4 * (L0 - L1), -4 * L1;
  dN.row(4) << 4 * L2, 4 * L1;
  dN.row(5) << -4 * L2, 4 * (L0 - L2);
}

double p2_min_jacobian(const Eigen::Matrix<double, 6, 2>& x) {
  Eigen::Matrix<double, 6, 1> N;
  Eigen::Matrix<double, 6, 2> dN;
  double m = std::numeric_limits<double>::infinity();
  auto check = [&](double xi, double eta) {
    p2_shape(xi, eta, N, dN);
    const Eigen::Matrix2d J = x.transpose() * dN;  // J(r, c) = d x_r / d xi_c
    m = std::min(m, J.determinant());
  };
  for (const auto& q : kRule) check(q.xi, q.eta);
  check(0, 0);
  check(1, 0);
  check(0, 1);
  return m;
}

bool assemble_p2p1_element(const P2ElementInput& in, const StabilisationParameters& stab, P2ElementOutput& out) {
  out.matrix.setZero();
  out.rhs.setZero();
  const double rho = in.density, mu = in.viscosity;
  const double gamma = stab.grad_div;
  Eigen::Matrix<double, 6, 1> N;
  Eigen::Matrix<double, 6, 2> dN, G;  // reference / physical gradients (rows)
  out.min_jacobian = std::numeric_limits<double>::infinity();

  // SUPG: element size and the Laplacians of the shape functions from the vertices' affine map.
  const bool supg = stab.supg;
  Eigen::Matrix<double, 6, 1> lap = Eigen::Matrix<double, 6, 1>::Zero();
  double h = 0;
  if (supg) {
    Eigen::Matrix2d Ja;
    Ja.col(0) = (in.x.row(1) - in.x.row(0)).transpose();
    Ja.col(1) = (in.x.row(2) - in.x.row(0)).transpose();
    const double det = Ja.determinant();
    if (!(det > 0)) {
      out.min_jacobian = det;
      return false;
    }
    const Eigen::Matrix2d Ji = Ja.inverse();
    static const auto H = reference_hessians();
    for (int k = 0; k < 6; ++k) lap(k) = (Ji.transpose() * H[static_cast<std::size_t>(k)] * Ji).trace();
    h = 0.5 * std::sqrt(4.0 * (0.5 * det) / std::sqrt(3.0));  // half the side of the equilateral triangle of equal area
  }

  for (const auto& q : kRule) {
    p2_shape(q.xi, q.eta, N, dN);
    const Eigen::Matrix2d J = in.x.transpose() * dN;
    const double det = J.determinant();
    out.min_jacobian = std::min(out.min_jacobian, det);
    if (!(det > 0)) return false;
    G = dN * J.inverse();
    const double w = 0.5 * q.weight * det;
    const Eigen::RowVector2d a = N.transpose() * in.advection;
    const Eigen::RowVector2d hist = N.transpose() * in.history;
    const Eigen::RowVector2d f = N.transpose() * in.force;
    const Eigen::Matrix<double, 6, 1> adv = G * a.transpose();  // a . grad N_k
    const Eigen::RowVector2d src = f - rho * hist;

    double tau = 0;
    if (supg) {
      const double nu = mu / rho;
      double inv_tau2 = std::pow(2.0 * a.norm() / h, 2) + std::pow(stab.viscous_constant * 4.0 * nu / (h * h), 2);
      if (stab.transient_tau && in.dt > 0) inv_tau2 += std::pow(2.0 / in.dt, 2);
      tau = 1.0 / std::sqrt(inv_tau2);
    }

    Eigen::Matrix2d Gu = Eigen::Matrix2d::Zero();  // Gu(c, d) = d u_k,c / d x_d
    Eigen::RowVector2d uk = Eigen::RowVector2d::Zero();
    if (in.newton) {
      Gu = in.velocity.transpose() * G;
      uk = N.transpose() * in.velocity;
    }
    for (int i = 0; i < 6; ++i) {
      const double test_supg = tau * rho * adv(i);
      for (int c = 0; c < 2; ++c) {
        double r = N(i) * src(c) + test_supg * src(c);
        if (in.newton) r += N(i) * rho * uk.dot(Gu.row(c));  // (w, rho (u_k . grad) u_k)
        out.rhs(2 * i + c) += w * r;
      }
      for (int j = 0; j < 6; ++j) {
        const double transport = rho * (in.alpha0_dt * N(j) + adv(j));
        const double vel = N(i) * transport + mu * G.row(i).dot(G.row(j)) + test_supg * (transport - mu * lap(j));
        for (int c = 0; c < 2; ++c) {
          out.matrix(2 * i + c, 2 * j + c) += w * vel;
          for (int d = 0; d < 2; ++d) {
            double v = gamma * G(i, c) * G(j, d);
            if (in.newton) v += rho * N(i) * N(j) * Gu(c, d);  // (w, rho (du . grad) u_k)
            out.matrix(2 * i + c, 2 * j + d) += w * v;
          }
        }
      }
      // pressure: -(div w, p) [+ SUPG (tau rho a.grad w, grad p)]; continuity (q, div u).
      const double L[3] = {1 - q.xi - q.eta, q.xi, q.eta};
      for (int j = 0; j < 3; ++j)
        for (int c = 0; c < 2; ++c) {
          const double v = -G(i, c) * L[j];
          out.matrix(2 * i + c, 12 + j) += w * v;
          out.matrix(12 + j, 2 * i + c) += w * L[j] * G(i, c);
        }
    }
    if (supg) {
      // grad of the linear pressure shape functions: L_j = sum of P2 shapes (L0 = N0 + (N3 + N5)/2, ...).
      Eigen::Matrix<double, 3, 2> GL;
      GL.row(0) = G.row(0) + 0.5 * (G.row(3) + G.row(5));
      GL.row(1) = G.row(1) + 0.5 * (G.row(3) + G.row(4));
      GL.row(2) = G.row(2) + 0.5 * (G.row(4) + G.row(5));
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 3; ++j)
          for (int c = 0; c < 2; ++c) out.matrix(2 * i + c, 12 + j) += w * tau * rho * adv(i) * GL(j, c);
    }
  }
  return true;
}

}  // namespace fsi::fluid
