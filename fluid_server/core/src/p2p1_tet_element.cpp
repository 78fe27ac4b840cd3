#include "fsi/fluid/p2p1_tet_element.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <limits>

#include "fsi/fluid/tet_mesh.hpp"

namespace fsi::fluid {

const std::array<TetQuadraturePoint, 14>& tet_quadrature() {
  static const std::array<TetQuadraturePoint, 14> rule = [] {
    std::array<TetQuadraturePoint, 14> r{};
    int n = 0;
    // Orbits (a, a, a, 1 - 3a) of 4 points and (b, b, 1/2 - b, 1/2 - b) of 6 points.
    const double a1 = 0.0927352503108912264, w1 = 0.0122488405193936582;
    const double a2 = 0.3108859192633006097, w2 = 0.0187813209530026417;
    const double b = 0.0455037041256496494, w3 = 0.0070910034628469110;
    for (const auto [a, w] : {std::pair{a1, w1}, std::pair{a2, w2}}) {
      const double c = 1 - 3 * a;
      r[n++] = {a, a, a, w};
      r[n++] = {c, a, a, w};
      r[n++] = {a, c, a, w};
      r[n++] = {a, a, c, w};
    }
    const double c = 0.5 - b;
    r[n++] = {b, b, c, w3};
    r[n++] = {b, c, b, w3};
    r[n++] = {c, b, b, w3};
    r[n++] = {c, c, b, w3};
    r[n++] = {c, b, c, w3};
    r[n++] = {b, c, c, w3};
    return r;
  }();
  return rule;
}

void p2_tet_shape(double x, double y, double z, Eigen::Matrix<double, 10, 1>& N, Eigen::Matrix<double, 10, 3>& dN) {
  const double L[4] = {1 - x - y - z, x, y, z};
  static const Eigen::Vector3d g[4] = {{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int k = 0; k < 4; ++k) {
    N(k) = L[k] * (2 * L[k] - 1);
    dN.row(k) = (4 * L[k] - 1) * g[k].transpose();
  }
  for (int k = 0; k < 6; ++k) {
    const int a = kTetEdges[k][0], b = kTetEdges[k][1];
    N(4 + k) = 4 * L[a] * L[b];
    dN.row(4 + k) = 4 * (L[a] * g[b] + L[b] * g[a]).transpose();
  }
}

double p2_tet_min_jacobian(const Eigen::Matrix<double, 10, 3>& x) {
  Eigen::Matrix<double, 10, 1> N;
  Eigen::Matrix<double, 10, 3> dN;
  double m = std::numeric_limits<double>::infinity();
  auto check = [&](double a, double b, double c) {
    p2_tet_shape(a, b, c, N, dN);
    m = std::min(m, (x.transpose() * dN).determinant());
  };
  for (const auto& q : tet_quadrature()) check(q.x, q.y, q.z);
  check(0, 0, 0);
  check(1, 0, 0);
  check(0, 1, 0);
  check(0, 0, 1);
  return m;
}

bool assemble_p2p1_tet(const P2TetInput& in, P2TetOutput& out) {
  out.matrix.setZero();
  out.rhs.setZero();
  const double rho = in.density, mu = in.viscosity, gamma = in.grad_div;
  Eigen::Matrix<double, 10, 1> N;
  Eigen::Matrix<double, 10, 3> dN, G;
  out.min_jacobian = std::numeric_limits<double>::infinity();
  // The velocity-velocity block per component pair, assembled as 10 x 10 scalar blocks.
  Eigen::Matrix<double, 10, 10> scalar = Eigen::Matrix<double, 10, 10>::Zero();
  for (const auto& q : tet_quadrature()) {
    p2_tet_shape(q.x, q.y, q.z, N, dN);
    const Eigen::Matrix3d J = in.x.transpose() * dN;
    const double det = J.determinant();
    out.min_jacobian = std::min(out.min_jacobian, det);
    if (!(det > 0)) return false;
    G = dN * J.inverse();
    const double w = q.weight * det;
    const Eigen::RowVector3d a = N.transpose() * in.advection;
    const Eigen::RowVector3d src = N.transpose() * in.force - rho * (N.transpose() * in.history);
    const Eigen::Matrix<double, 10, 1> adv = G * a.transpose();
    const double L[4] = {1 - q.x - q.y - q.z, q.x, q.y, q.z};
    Eigen::Matrix3d Gu = Eigen::Matrix3d::Zero();  // Gu(c, d) = d u_k,c / d x_d
    Eigen::RowVector3d uk = Eigen::RowVector3d::Zero();
    if (in.newton) {
      Gu = in.velocity.transpose() * G;
      uk = N.transpose() * in.velocity;
    }
    // Scalar part: rho (alpha0/dt N_j + a.grad N_j) N_i + mu grad N_i . grad N_j.
    scalar.noalias() += w * (N * (rho * (in.alpha0_dt * N + adv)).transpose() + mu * G * G.transpose());
    for (int i = 0; i < 10; ++i) {
      for (int c = 0; c < 3; ++c) {
        double r = N(i) * src(c);
        if (in.newton) r += N(i) * rho * uk.dot(Gu.row(c));
        out.rhs(3 * i + c) += w * r;
      }
      if (in.newton || gamma != 0)
        for (int j = 0; j < 10; ++j)
          for (int c = 0; c < 3; ++c)
            for (int d = 0; d < 3; ++d) {
              double v = gamma * G(i, c) * G(j, d);
              if (in.newton) v += rho * N(i) * N(j) * Gu(c, d);
              out.matrix(3 * i + c, 3 * j + d) += w * v;
            }
      for (int j = 0; j < 4; ++j)
        for (int c = 0; c < 3; ++c) {
          out.matrix(3 * i + c, 30 + j) -= w * G(i, c) * L[j];
          out.matrix(30 + j, 3 * i + c) += w * L[j] * G(i, c);
        }
    }
  }
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int c = 0; c < 3; ++c) out.matrix(3 * i + c, 3 * j + c) += scalar(i, j);
  return true;
}

}  // namespace fsi::fluid
