#include "fsi/solid/element.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace fsi::solid {

namespace {
constexpr double kXi[4] = {-1, 1, 1, -1};
constexpr double kEta[4] = {-1, -1, 1, 1};
}  // namespace

Eigen::Vector4d q4_shape(double xi, double eta) {
  Eigen::Vector4d N;
  for (int a = 0; a < 4; ++a) N(a) = 0.25 * (1 + kXi[a] * xi) * (1 + kEta[a] * eta);
  return N;
}

Eigen::Matrix<double, 4, 2> q4_shape_derivatives(double xi, double eta) {
  Eigen::Matrix<double, 4, 2> dN;
  for (int a = 0; a < 4; ++a) {
    dN(a, 0) = 0.25 * kXi[a] * (1 + kEta[a] * eta);
    dN(a, 1) = 0.25 * kEta[a] * (1 + kXi[a] * xi);
  }
  return dN;
}

std::vector<std::array<double, 3>> gauss_rule_2d(int n) {
  std::vector<double> x, w;
  if (n == 1) {
    x = {0};
    w = {2};
  } else if (n == 2) {
    const double g = 1.0 / std::sqrt(3.0);
    x = {-g, g};
    w = {1, 1};
  } else if (n == 3) {
    const double g = std::sqrt(0.6);
    x = {-g, 0, g};
    w = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  } else {
    throw std::invalid_argument("gauss_rule_2d: n must be 1, 2 or 3");
  }
  std::vector<std::array<double, 3>> rule;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = 0; j < x.size(); ++j) rule.push_back({x[i], x[j], w[i] * w[j]});
  return rule;
}

namespace {
const std::vector<std::array<double, 3>>& gauss2() {
  static const auto rule = gauss_rule_2d(2);
  return rule;
}

// Reference-configuration gradients dN/dX (4x2) and det of the Jacobian.
double reference_gradients(const ElementCoords& X, double xi, double eta, Eigen::Matrix<double, 4, 2>& dNdX) {
  const Eigen::Matrix<double, 4, 2> dN = q4_shape_derivatives(xi, eta);
  const Eigen::Matrix2d Jac = X.transpose() * dN;  // dX/dxi
  const double det = Jac.determinant();
  dNdX = dN * Jac.inverse();
  return det;
}
}  // namespace

Matrix2 q4_deformation_gradient(const ElementCoords& X, const ElementVector& u, double xi, double eta) {
  Eigen::Matrix<double, 4, 2> dNdX;
  reference_gradients(X, xi, eta, dNdX);
  const Eigen::Map<const Eigen::Matrix<double, 2, 4>> U(u.data());  // column per node
  return Matrix2::Identity() + U * dNdX;
}

ElementState q4_internal_force(const ElementCoords& X, const ElementVector& u, const Material& material,
                               bool with_tangent) {
  ElementState out;
  const Eigen::Map<const Eigen::Matrix<double, 2, 4>> U(u.data());
  for (const auto& [xi, eta, w] : gauss2()) {
    Eigen::Matrix<double, 4, 2> dNdX;
    const double detJ = reference_gradients(X, xi, eta, dNdX);
    out.min_det_jacobian = std::min(out.min_det_jacobian, detJ);
    const Kinematics k = Kinematics::from_displacement_gradient(U * dNdX);
    const Matrix2& F = k.F;
    out.min_det_F = std::min(out.min_det_F, k.J);
    if (!(k.J > 0)) continue;  // the caller reports; keep values finite
    const Vector3 S = material.stress(k);
    const double dV = w * detJ;
    // Nonlinear strain-displacement matrix: dE_voigt = B du.
    Eigen::Matrix<double, 3, 8> B;
    for (int a = 0; a < 4; ++a) {
      const double n1 = dNdX(a, 0), n2 = dNdX(a, 1);
      B(0, 2 * a) = F(0, 0) * n1;
      B(0, 2 * a + 1) = F(1, 0) * n1;
      B(1, 2 * a) = F(0, 1) * n2;
      B(1, 2 * a + 1) = F(1, 1) * n2;
      B(2, 2 * a) = F(0, 0) * n2 + F(0, 1) * n1;
      B(2, 2 * a + 1) = F(1, 0) * n2 + F(1, 1) * n1;
    }
    out.internal_force.noalias() += dV * B.transpose() * S;
    if (!with_tangent) continue;
    const Matrix3 D = material.tangent(k);
    out.tangent.noalias() += dV * B.transpose() * D * B;
    Matrix2 Sm;
    Sm << S(0), S(2), S(2), S(1);
    const Eigen::Matrix4d G = dNdX * Sm * dNdX.transpose();  // geometric stiffness per node pair
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        out.tangent(2 * a, 2 * b) += dV * G(a, b);
        out.tangent(2 * a + 1, 2 * b + 1) += dV * G(a, b);
      }
  }
  return out;
}

ElementState q4_eas_internal_force(const ElementCoords& X, const ElementVector& u, const Material& material,
                                   bool with_tangent) {
  // Strain transformation at the centre: natural (covariant) strains -> Voigt [E11, E22, 2 E12].
  const Eigen::Matrix2d J0 = X.transpose() * q4_shape_derivatives(0, 0);  // dX/dxi
  const double det0 = J0.determinant();
  const Eigen::Matrix2d K = J0.inverse();  // K(A, j) = dxi_A / dX_j
  Eigen::Matrix3d T0;
  T0 << K(0, 0) * K(0, 0), K(1, 0) * K(1, 0), K(0, 0) * K(1, 0), K(0, 1) * K(0, 1), K(1, 1) * K(1, 1),
      K(0, 1) * K(1, 1), 2 * K(0, 0) * K(0, 1), 2 * K(1, 0) * K(1, 1), K(0, 0) * K(1, 1) + K(1, 0) * K(0, 1);
  const Eigen::Map<const Eigen::Matrix<double, 2, 4>> U(u.data());
  struct Point {
    double dV;
    Eigen::Matrix<double, 3, 8> B;
    Eigen::Matrix<double, 3, 4> G;
    Eigen::Vector3d Ec;
    Eigen::Matrix<double, 4, 2> dNdX;
    Matrix2 F;
  };
  std::array<Point, 4> pts;
  ElementState out;
  int g = 0;
  for (const auto& [xi, eta, w] : gauss2()) {
    Point& p = pts[static_cast<std::size_t>(g++)];
    const double detJ = reference_gradients(X, xi, eta, p.dNdX);
    out.min_det_jacobian = std::min(out.min_det_jacobian, detJ);
    p.dV = w * detJ;
    const Kinematics kc = Kinematics::from_displacement_gradient(U * p.dNdX);
    p.F = kc.F;
    out.min_det_F = std::min(out.min_det_F, kc.J);
    p.Ec << kc.E(0, 0), kc.E(1, 1), 2 * kc.E(0, 1);
    const Matrix2& F = p.F;
    for (int a = 0; a < 4; ++a) {
      const double n1 = p.dNdX(a, 0), n2 = p.dNdX(a, 1);
      p.B(0, 2 * a) = F(0, 0) * n1;
      p.B(0, 2 * a + 1) = F(1, 0) * n1;
      p.B(1, 2 * a) = F(0, 1) * n2;
      p.B(1, 2 * a + 1) = F(1, 1) * n2;
      p.B(2, 2 * a) = F(0, 0) * n2 + F(0, 1) * n1;
      p.B(2, 2 * a + 1) = F(1, 0) * n2 + F(1, 1) * n1;
    }
    Eigen::Matrix<double, 3, 4> M = Eigen::Matrix<double, 3, 4>::Zero();
    M(0, 0) = xi;
    M(1, 1) = eta;
    M(2, 2) = xi;
    M(2, 3) = eta;
    p.G = (det0 / detJ) * T0 * M;
  }
  if (!(out.min_det_F > 0)) return out;  // the caller reports the inverted element
  auto kinematics = [](const Point& p, const Eigen::Vector3d& e) {
    Matrix2 E;
    E << e(0), 0.5 * e(2), 0.5 * e(2), e(1);
    return Kinematics::from_green_lagrange(E, p.F);
  };
  // Local Newton for the enhanced parameters: h(alpha) = int G^T S dV = 0.
  Eigen::Vector4d alpha = Eigen::Vector4d::Zero();
  Eigen::Matrix4d Kaa;
  for (int it = 0; it < 25; ++it) {
    Eigen::Vector4d h = Eigen::Vector4d::Zero();
    Kaa.setZero();
    bool ok = true;
    for (const Point& p : pts) {
      const Kinematics k = kinematics(p, p.Ec + p.G * alpha);
      if (!(k.J > 0)) {
        ok = false;
        break;
      }
      h.noalias() += p.dV * p.G.transpose() * material.stress(k);
      Kaa.noalias() += p.dV * p.G.transpose() * material.tangent(k) * p.G;
    }
    if (!ok) {
      out.min_det_F = std::min(out.min_det_F, -1.0);
      return out;
    }
    const Eigen::Vector4d step = Kaa.ldlt().solve(h);
    alpha -= step;
    if (!alpha.allFinite()) {
      out.min_det_F = std::min(out.min_det_F, -1.0);
      return out;
    }
    if (step.cwiseAbs().maxCoeff() <= 1e-15 + 1e-13 * alpha.cwiseAbs().maxCoeff()) break;
  }
  // Force and condensed tangent at the converged alpha.
  Eigen::Matrix<double, 8, 4> Kua = Eigen::Matrix<double, 8, 4>::Zero();
  Kaa.setZero();
  for (const Point& p : pts) {
    const Kinematics k = kinematics(p, p.Ec + p.G * alpha);
    out.min_det_F = std::min(out.min_det_F, k.J);
    if (!(k.J > 0)) return out;
    const Vector3 S = material.stress(k);
    out.internal_force.noalias() += p.dV * p.B.transpose() * S;
    if (!with_tangent) continue;
    const Matrix3 D = material.tangent(k);
    out.tangent.noalias() += p.dV * p.B.transpose() * D * p.B;
    Kua.noalias() += p.dV * p.B.transpose() * D * p.G;
    Kaa.noalias() += p.dV * p.G.transpose() * D * p.G;
    Matrix2 Sm;
    Sm << S(0), S(2), S(2), S(1);
    const Eigen::Matrix4d Gm = p.dNdX * Sm * p.dNdX.transpose();
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        out.tangent(2 * a, 2 * b) += p.dV * Gm(a, b);
        out.tangent(2 * a + 1, 2 * b + 1) += p.dV * Gm(a, b);
      }
  }
  if (with_tangent) out.tangent.noalias() -= Kua * Kaa.ldlt().solve(Kua.transpose());
  return out;
}

ElementMatrix q4_mass(const ElementCoords& X, double density) {
  ElementMatrix M = ElementMatrix::Zero();
  for (const auto& [xi, eta, w] : gauss2()) {
    Eigen::Matrix<double, 4, 2> dNdX;
    const double dV = w * reference_gradients(X, xi, eta, dNdX);
    const Eigen::Vector4d N = q4_shape(xi, eta);
    const Eigen::Matrix4d m = density * dV * N * N.transpose();
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) {
        M(2 * a, 2 * b) += m(a, b);
        M(2 * a + 1, 2 * b + 1) += m(a, b);
      }
  }
  return M;
}

ElementVector q4_body_force(const ElementCoords& X, const Eigen::Vector2d& b) {
  ElementVector f = ElementVector::Zero();
  for (const auto& [xi, eta, w] : gauss2()) {
    Eigen::Matrix<double, 4, 2> dNdX;
    const double dV = w * reference_gradients(X, xi, eta, dNdX);
    const Eigen::Vector4d N = q4_shape(xi, eta);
    for (int a = 0; a < 4; ++a) f.segment<2>(2 * a) += dV * N(a) * b;
  }
  return f;
}

Eigen::Matrix4d edge_mass(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double weight) {
  const double L = (b - a).norm();
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  const double d = weight * L / 3.0, o = weight * L / 6.0;
  M(0, 0) = M(1, 1) = M(2, 2) = M(3, 3) = d;
  M(0, 2) = M(2, 0) = M(1, 3) = M(3, 1) = o;
  return M;
}

bool q4_inverse_map(const ElementCoords& X, const Eigen::Vector2d& p, Eigen::Vector2d& xi) {
  xi.setZero();
  for (int it = 0; it < 30; ++it) {
    const Eigen::Vector2d x = X.transpose() * q4_shape(xi(0), xi(1));
    const Eigen::Matrix2d Jac = X.transpose() * q4_shape_derivatives(xi(0), xi(1));
    const Eigen::Vector2d dxi = Jac.inverse() * (p - x);
    xi += dxi;
    if (!xi.allFinite() || xi.cwiseAbs().maxCoeff() > 10) return false;
    if (dxi.norm() < 1e-12) return true;
  }
  return xi.allFinite();  // converged to round-off
}

}  // namespace fsi::solid
