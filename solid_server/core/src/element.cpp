#include "fsi/solid/element.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "fsi/common/interface_geometry.hpp"

namespace fsi::solid {

namespace {
constexpr double kXi[4] = {-1, 1, 1, -1};
constexpr double kEta[4] = {-1, -1, 1, 1};
// Hex8: the Q4's corners at zeta = -1, then at zeta = +1.
constexpr double kHexXi[8] = {-1, 1, 1, -1, -1, 1, 1, -1};
constexpr double kHexEta[8] = {-1, -1, 1, 1, -1, -1, 1, 1};
constexpr double kHexZeta[8] = {-1, -1, -1, -1, 1, 1, 1, 1};
const double kGauss = 1.0 / std::sqrt(3.0);
}  // namespace

// ---------------------------------------------------------------- shapes
Eigen::Matrix<double, 4, 1> Quad4::shape(const Point& p) {
  Eigen::Vector4d N;
  for (int a = 0; a < 4; ++a) N(a) = 0.25 * (1 + kXi[a] * p(0)) * (1 + kEta[a] * p(1));
  return N;
}

Eigen::Matrix<double, 4, 2> Quad4::derivatives(const Point& p) {
  Eigen::Matrix<double, 4, 2> dN;
  for (int a = 0; a < 4; ++a) {
    dN(a, 0) = 0.25 * kXi[a] * (1 + kEta[a] * p(1));
    dN(a, 1) = 0.25 * kEta[a] * (1 + kXi[a] * p(0));
  }
  return dN;
}

const std::array<std::pair<Quad4::Point, double>, 4>& Quad4::gauss() {
  static const std::array<std::pair<Point, double>, 4> rule = {
      {{{-kGauss, -kGauss}, 1}, {{-kGauss, kGauss}, 1}, {{kGauss, -kGauss}, 1}, {{kGauss, kGauss}, 1}}};
  return rule;
}

Eigen::Matrix<double, 3, 4> Quad4::enhanced_modes(const Point& p) {
  Eigen::Matrix<double, 3, 4> M = Eigen::Matrix<double, 3, 4>::Zero();
  M(0, 0) = p(0);
  M(1, 1) = p(1);
  M(2, 2) = p(0);
  M(2, 3) = p(1);
  return M;
}

Eigen::Matrix<double, 8, 1> Hex8::shape(const Point& p) {
  Eigen::Matrix<double, 8, 1> N;
  for (int a = 0; a < 8; ++a)
    N(a) = 0.125 * (1 + kHexXi[a] * p(0)) * (1 + kHexEta[a] * p(1)) * (1 + kHexZeta[a] * p(2));
  return N;
}

Eigen::Matrix<double, 8, 3> Hex8::derivatives(const Point& p) {
  Eigen::Matrix<double, 8, 3> dN;
  for (int a = 0; a < 8; ++a) {
    const double fx = 1 + kHexXi[a] * p(0), fy = 1 + kHexEta[a] * p(1), fz = 1 + kHexZeta[a] * p(2);
    dN(a, 0) = 0.125 * kHexXi[a] * fy * fz;
    dN(a, 1) = 0.125 * kHexEta[a] * fx * fz;
    dN(a, 2) = 0.125 * kHexZeta[a] * fx * fy;
  }
  return dN;
}

const std::array<std::pair<Hex8::Point, double>, 8>& Hex8::gauss() {
  static const std::array<std::pair<Point, double>, 8> rule = [] {
    std::array<std::pair<Point, double>, 8> r;
    int g = 0;
    for (double x : {-kGauss, kGauss})
      for (double y : {-kGauss, kGauss})
        for (double z : {-kGauss, kGauss}) r[static_cast<std::size_t>(g++)] = {Point(x, y, z), 1.0};
    return r;
  }();
  return rule;
}

Eigen::Matrix<double, 6, 9> Hex8::enhanced_modes(const Point& p) {
  // Natural strains [xixi, etaeta, zetazeta, 2 xieta, 2 etazeta, 2 xizeta].
  Eigen::Matrix<double, 6, 9> M = Eigen::Matrix<double, 6, 9>::Zero();
  M(0, 0) = p(0);
  M(1, 1) = p(1);
  M(2, 2) = p(2);
  M(3, 3) = p(0);
  M(3, 4) = p(1);
  M(4, 5) = p(1);
  M(4, 6) = p(2);
  M(5, 7) = p(0);
  M(5, 8) = p(2);
  return M;
}

// Tet10: barycentric L0 = 1 - xi - eta - zeta, L1 = xi, L2 = eta, L3 = zeta; vertices
// L_a (2 L_a - 1), edge midpoints 4 L_a L_b.
namespace {
constexpr int kTetEdges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {2, 3}, {1, 3}};
// dL_a/dxi.
constexpr double kTetDL[4][3] = {{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
}  // namespace

Eigen::Matrix<double, 10, 1> Tet10::shape(const Point& p) {
  const double L[4] = {1 - p(0) - p(1) - p(2), p(0), p(1), p(2)};
  Eigen::Matrix<double, 10, 1> N;
  for (int a = 0; a < 4; ++a) N(a) = L[a] * (2 * L[a] - 1);
  for (int e = 0; e < 6; ++e) N(4 + e) = 4 * L[kTetEdges[e][0]] * L[kTetEdges[e][1]];
  return N;
}

Eigen::Matrix<double, 10, 3> Tet10::derivatives(const Point& p) {
  const double L[4] = {1 - p(0) - p(1) - p(2), p(0), p(1), p(2)};
  Eigen::Matrix<double, 10, 3> dN;
  for (int k = 0; k < 3; ++k) {
    for (int a = 0; a < 4; ++a) dN(a, k) = (4 * L[a] - 1) * kTetDL[a][k];
    for (int e = 0; e < 6; ++e) {
      const int a = kTetEdges[e][0], b = kTetEdges[e][1];
      dN(4 + e, k) = 4 * (kTetDL[a][k] * L[b] + L[a] * kTetDL[b][k]);
    }
  }
  return dN;
}

const std::array<std::pair<Tet10::Point, double>, 14>& Tet10::gauss() {
  // Walkington's 14-point rule, degree 5, positive weights (reference volume 1/6): the
  // 4 + 4 points (a, a, a, 1 - 3a) and the 6 points (b, b, 1/2 - b, 1/2 - b) in barycentric
  // coordinates.
  static const std::array<std::pair<Point, double>, 14> rule = [] {
    std::array<std::pair<Point, double>, 14> r;
    std::size_t g = 0;
    auto add = [&](const std::array<double, 4>& L, double w) { r[g++] = {Point(L[1], L[2], L[3]), w}; };
    for (const auto& [a, w] : {std::pair<double, double>{0.0927352503108912264, 0.01224884051939366},
                               std::pair<double, double>{0.3108859192633006097, 0.01878132095300264}}) {
      const double b = 1 - 3 * a;
      add({b, a, a, a}, w), add({a, b, a, a}, w), add({a, a, b, a}, w), add({a, a, a, b}, w);
    }
    const double a = 0.0455037041256496494, b = 0.5 - a, w = 0.007091003462846911;
    add({a, a, b, b}, w), add({a, b, a, b}, w), add({a, b, b, a}, w);
    add({b, a, a, b}, w), add({b, a, b, a}, w), add({b, b, a, a}, w);
    return r;
  }();
  return rule;
}

const std::array<std::array<int, 6>, 4>& Tet10::faces() {
  // Vertices (a, b, c), then the midpoints of a-b, b-c, c-a (node 4 + edge index).
  static const std::array<std::array<int, 6>, 4> f = {{{0, 2, 1, 6, 5, 4},  //
                                                       {0, 1, 3, 4, 9, 7},
                                                       {1, 2, 3, 5, 8, 9},
                                                       {0, 3, 2, 7, 8, 6}}};
  return f;
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

// ---------------------------------------------------------------- kernels
namespace {

// Reference-configuration gradients dN/dX (nodes x dim) and det of the Jacobian.
template <class Shape>
double reference_gradients(const typename ElementTraits<Shape>::Coords& X, const typename Shape::Point& xi,
                           Eigen::Matrix<double, Shape::nodes, Shape::dim>& dNdX) {
  using Tensor = typename ElementTraits<Shape>::Tensor;
  const Eigen::Matrix<double, Shape::nodes, Shape::dim> dN = Shape::derivatives(xi);
  const Tensor Jac = X.transpose() * dN;  // dX/dxi
  const double det = Jac.determinant();
  dNdX = dN * Jac.inverse();
  return det;
}

// Voigt pairs of the strain rows: normal components first, then the shears.
template <int dim>
constexpr std::array<std::array<int, 2>, voigt_size<dim>> strain_pairs() {
  if constexpr (dim == 2)
    return {{{0, 0}, {1, 1}, {0, 1}}};
  else
    return {{{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}}};
}

// Nonlinear strain-displacement matrix: dE_voigt = B du (shears doubled).
template <class Shape>
Eigen::Matrix<double, voigt_size<Shape::dim>, ElementTraits<Shape>::dofs> strain_displacement(
    const Eigen::Matrix<double, Shape::nodes, Shape::dim>& dNdX, const typename ElementTraits<Shape>::Tensor& F) {
  constexpr int dim = Shape::dim;
  constexpr auto pairs = strain_pairs<dim>();
  Eigen::Matrix<double, voigt_size<dim>, ElementTraits<Shape>::dofs> B;
  for (int a = 0; a < Shape::nodes; ++a)
    for (int s = 0; s < voigt_size<dim>; ++s) {
      const int i = pairs[s][0], j = pairs[s][1];
      for (int c = 0; c < dim; ++c)
        B(s, dim * a + c) = i == j ? F(c, i) * dNdX(a, i) : F(c, i) * dNdX(a, j) + F(c, j) * dNdX(a, i);
    }
  return B;
}

// Geometric stiffness int Grad N S Grad N^T dV on the diagonal dof blocks.
template <class Shape>
void add_geometric_stiffness(typename ElementTraits<Shape>::Matrix& K,
                             const Eigen::Matrix<double, Shape::nodes, Shape::dim>& dNdX,
                             const Eigen::Matrix<double, voigt_size<Shape::dim>, 1>& S, double dV) {
  constexpr int dim = Shape::dim, n = Shape::nodes;
  const Eigen::Matrix<double, dim, dim> Sm = from_voigt<dim>(S);
  const Eigen::Matrix<double, n, n> G = dNdX * Sm * dNdX.transpose();  // per node pair
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int c = 0; c < dim; ++c) K(dim * a + c, dim * b + c) += dV * G(a, b);
}

// Natural strains (Voigt, doubled shears) -> Cartesian strains with K = J^-1, K(A, j) = dxi_A/dX_j:
// E_ij = K(A, i) K(B, j) E_AB.
template <int dim>
Eigen::Matrix<double, voigt_size<dim>, voigt_size<dim>> strain_transformation(
    const Eigen::Matrix<double, dim, dim>& K) {
  constexpr auto pairs = strain_pairs<dim>();
  Eigen::Matrix<double, voigt_size<dim>, voigt_size<dim>> T;
  for (int a = 0; a < voigt_size<dim>; ++a)
    for (int b = 0; b < voigt_size<dim>; ++b) {
      const int i = pairs[a][0], j = pairs[a][1], A = pairs[b][0], Bn = pairs[b][1];
      if (i == j)
        T(a, b) = K(A, i) * K(Bn, i);
      else if (A == Bn)
        T(a, b) = 2 * K(A, i) * K(A, j);
      else
        T(a, b) = K(A, i) * K(Bn, j) + K(Bn, i) * K(A, j);
    }
  return T;
}

}  // namespace

template <class Shape>
typename ElementTraits<Shape>::Tensor deformation_gradient(const typename ElementTraits<Shape>::Coords& X,
                                                           const typename ElementTraits<Shape>::Vector& u,
                                                           const typename Shape::Point& xi) {
  constexpr int dim = Shape::dim;
  Eigen::Matrix<double, Shape::nodes, dim> dNdX;
  reference_gradients<Shape>(X, xi, dNdX);
  const Eigen::Map<const Eigen::Matrix<double, dim, Shape::nodes>> U(u.data());  // column per node
  return ElementTraits<Shape>::Tensor::Identity() + U * dNdX;
}

template <class Shape>
ElementStateT<Shape> internal_force(const typename ElementTraits<Shape>::Coords& X,
                                    const typename ElementTraits<Shape>::Vector& u,
                                    const MaterialLaw<Shape::dim>& material, bool with_tangent) {
  constexpr int dim = Shape::dim;
  using Law = MaterialLaw<dim>;
  ElementStateT<Shape> out;
  const Eigen::Map<const Eigen::Matrix<double, dim, Shape::nodes>> U(u.data());
  for (const auto& [xi, w] : Shape::gauss()) {
    Eigen::Matrix<double, Shape::nodes, dim> dNdX;
    const double detJ = reference_gradients<Shape>(X, xi, dNdX);
    out.min_det_jacobian = std::min(out.min_det_jacobian, detJ);
    const KinematicsT<dim> k = KinematicsT<dim>::from_displacement_gradient(U * dNdX);
    out.min_det_F = std::min(out.min_det_F, k.J);
    if (!(k.J > 0)) continue;  // the caller reports; keep values finite
    const typename Law::Stress S = material.stress(k);
    const double dV = w * detJ;
    const auto B = strain_displacement<Shape>(dNdX, k.F);
    out.internal_force.noalias() += dV * B.transpose() * S;
    if (!with_tangent) continue;
    const typename Law::Tangent D = material.tangent(k);
    out.tangent.noalias() += dV * B.transpose() * D * B;
    add_geometric_stiffness<Shape>(out.tangent, dNdX, S, dV);
  }
  return out;
}

template <class Shape>
ElementStateT<Shape> eas_internal_force(const typename ElementTraits<Shape>::Coords& X,
                                        const typename ElementTraits<Shape>::Vector& u,
                                        const MaterialLaw<Shape::dim>& material, bool with_tangent) {
  constexpr int dim = Shape::dim, nv = voigt_size<dim>, nm = Shape::eas_modes, nd = ElementTraits<Shape>::dofs;
  using Tensor = typename ElementTraits<Shape>::Tensor;
  using Law = MaterialLaw<dim>;
  using Modes = Eigen::Matrix<double, nm, 1>;
  using ModeMatrix = Eigen::Matrix<double, nm, nm>;
  // Strain transformation at the centre: natural (covariant) strains -> Voigt strains.
  const Tensor J0 = X.transpose() * Shape::derivatives(Shape::Point::Zero());  // dX/dxi
  const double det0 = J0.determinant();
  const Eigen::Matrix<double, nv, nv> T0 = strain_transformation<dim>(Tensor(J0.inverse()));
  const Eigen::Map<const Eigen::Matrix<double, dim, Shape::nodes>> U(u.data());
  struct Point {
    double dV;
    Eigen::Matrix<double, nv, nd> B;
    Eigen::Matrix<double, nv, nm> G;
    Eigen::Matrix<double, nv, 1> Ec;
    Eigen::Matrix<double, Shape::nodes, dim> dNdX;
    Tensor F;
  };
  std::array<Point, Shape::gauss_points> pts;
  ElementStateT<Shape> out;
  int g = 0;
  for (const auto& [xi, w] : Shape::gauss()) {
    Point& p = pts[static_cast<std::size_t>(g++)];
    const double detJ = reference_gradients<Shape>(X, xi, p.dNdX);
    out.min_det_jacobian = std::min(out.min_det_jacobian, detJ);
    p.dV = w * detJ;
    const KinematicsT<dim> kc = KinematicsT<dim>::from_displacement_gradient(U * p.dNdX);
    p.F = kc.F;
    out.min_det_F = std::min(out.min_det_F, kc.J);
    constexpr auto pairs = strain_pairs<dim>();
    for (int s = 0; s < nv; ++s) {
      const int i = pairs[s][0], j = pairs[s][1];
      p.Ec(s) = i == j ? kc.E(i, i) : 2 * kc.E(i, j);
    }
    p.B = strain_displacement<Shape>(p.dNdX, p.F);
    p.G = (det0 / detJ) * T0 * Shape::enhanced_modes(xi);
  }
  if (!(out.min_det_F > 0)) return out;  // the caller reports the inverted element
  auto kinematics = [](const Point& p, const Eigen::Matrix<double, nv, 1>& e) {
    Tensor E = from_voigt<dim>(e);
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j)
        if (i != j) E(i, j) *= 0.5;
    return KinematicsT<dim>::from_green_lagrange(E, p.F);
  };
  // Local Newton for the enhanced parameters: h(alpha) = int G^T S dV = 0.
  Modes alpha = Modes::Zero();
  ModeMatrix Kaa;
  for (int it = 0; it < 25; ++it) {
    Modes h = Modes::Zero();
    Kaa.setZero();
    bool ok = true;
    for (const Point& p : pts) {
      const KinematicsT<dim> k = kinematics(p, p.Ec + p.G * alpha);
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
    const Modes step = Kaa.ldlt().solve(h);
    alpha -= step;
    if (!alpha.allFinite()) {
      out.min_det_F = std::min(out.min_det_F, -1.0);
      return out;
    }
    if (step.cwiseAbs().maxCoeff() <= 1e-15 + 1e-13 * alpha.cwiseAbs().maxCoeff()) break;
  }
  // Force and condensed tangent at the converged alpha.
  Eigen::Matrix<double, nd, nm> Kua = Eigen::Matrix<double, nd, nm>::Zero();
  Kaa.setZero();
  for (const Point& p : pts) {
    const KinematicsT<dim> k = kinematics(p, p.Ec + p.G * alpha);
    out.min_det_F = std::min(out.min_det_F, k.J);
    if (!(k.J > 0)) return out;
    const typename Law::Stress S = material.stress(k);
    out.internal_force.noalias() += p.dV * p.B.transpose() * S;
    if (!with_tangent) continue;
    const typename Law::Tangent D = material.tangent(k);
    out.tangent.noalias() += p.dV * p.B.transpose() * D * p.B;
    Kua.noalias() += p.dV * p.B.transpose() * D * p.G;
    Kaa.noalias() += p.dV * p.G.transpose() * D * p.G;
    add_geometric_stiffness<Shape>(out.tangent, p.dNdX, S, p.dV);
  }
  if (with_tangent) out.tangent.noalias() -= Kua * Kaa.ldlt().solve(Kua.transpose());
  return out;
}

template <class Shape>
typename ElementTraits<Shape>::Matrix element_mass(const typename ElementTraits<Shape>::Coords& X, double density) {
  constexpr int dim = Shape::dim, n = Shape::nodes;
  using Matrix = typename ElementTraits<Shape>::Matrix;
  Matrix M = Matrix::Zero();
  for (const auto& [xi, w] : Shape::gauss()) {
    Eigen::Matrix<double, n, dim> dNdX;
    const double dV = w * reference_gradients<Shape>(X, xi, dNdX);
    const Eigen::Matrix<double, n, 1> N = Shape::shape(xi);
    const Eigen::Matrix<double, n, n> m = density * dV * N * N.transpose();
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        for (int c = 0; c < dim; ++c) M(dim * a + c, dim * b + c) += m(a, b);
  }
  return M;
}

template <class Shape>
typename ElementTraits<Shape>::Vector element_body_force(const typename ElementTraits<Shape>::Coords& X,
                                                         const Eigen::Matrix<double, Shape::dim, 1>& b) {
  constexpr int dim = Shape::dim, n = Shape::nodes;
  using Vector = typename ElementTraits<Shape>::Vector;
  Vector f = Vector::Zero();
  for (const auto& [xi, w] : Shape::gauss()) {
    Eigen::Matrix<double, n, dim> dNdX;
    const double dV = w * reference_gradients<Shape>(X, xi, dNdX);
    const Eigen::Matrix<double, n, 1> N = Shape::shape(xi);
    for (int a = 0; a < n; ++a) f.template segment<dim>(dim * a) += dV * N(a) * b;
  }
  return f;
}

template <class Shape>
bool inverse_map(const typename ElementTraits<Shape>::Coords& X, const typename Shape::Point& p,
                 typename Shape::Point& xi) {
  using Tensor = typename ElementTraits<Shape>::Tensor;
  using Point = typename Shape::Point;
  xi = Shape::centre();
  for (int it = 0; it < 30; ++it) {
    const Point x = X.transpose() * Shape::shape(xi);
    const Tensor Jac = X.transpose() * Shape::derivatives(xi);
    const Point dxi = Jac.inverse() * (p - x);
    xi += dxi;
    if (!xi.allFinite() || xi.cwiseAbs().maxCoeff() > 10) return false;
    if (dxi.norm() < 1e-12) return true;
  }
  return xi.allFinite();  // converged to round-off
}

#define FSI_SOLID_INSTANTIATE_EAS(Shape)                   \
  template ElementStateT<Shape> eas_internal_force<Shape>( \
      const ElementTraits<Shape>::Coords&, const ElementTraits<Shape>::Vector&, const MaterialLaw<Shape::dim>&, bool);
#define FSI_SOLID_INSTANTIATE(Shape)                                                                                   \
  template ElementStateT<Shape> internal_force<Shape>(                                                                 \
      const ElementTraits<Shape>::Coords&, const ElementTraits<Shape>::Vector&, const MaterialLaw<Shape::dim>&, bool); \
  template ElementTraits<Shape>::Matrix element_mass<Shape>(const ElementTraits<Shape>::Coords&, double);              \
  template ElementTraits<Shape>::Vector element_body_force<Shape>(const ElementTraits<Shape>::Coords&,                 \
                                                                  const Eigen::Matrix<double, Shape::dim, 1>&);        \
  template ElementTraits<Shape>::Tensor deformation_gradient<Shape>(                                                   \
      const ElementTraits<Shape>::Coords&, const ElementTraits<Shape>::Vector&, const Shape::Point&);                  \
  template bool inverse_map<Shape>(const ElementTraits<Shape>::Coords&, const Shape::Point&, Shape::Point&);
FSI_SOLID_INSTANTIATE(Quad4)
FSI_SOLID_INSTANTIATE(Hex8)
FSI_SOLID_INSTANTIATE(Tet10)
FSI_SOLID_INSTANTIATE_EAS(Quad4)
FSI_SOLID_INSTANTIATE_EAS(Hex8)
#undef FSI_SOLID_INSTANTIATE
#undef FSI_SOLID_INSTANTIATE_EAS

Eigen::Matrix4d edge_mass(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double weight) {
  const double L = (b - a).norm();
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  const double d = weight * L / 3.0, o = weight * L / 6.0;
  M(0, 0) = M(1, 1) = M(2, 2) = M(3, 3) = d;
  M(0, 2) = M(2, 0) = M(1, 3) = M(3, 1) = o;
  return M;
}

Eigen::Vector4d quad_face_weights(const Eigen::Matrix<double, 4, 3>& X) {
  Eigen::Vector4d out = Eigen::Vector4d::Zero();
  for (const auto& [xi, w] : Quad4::gauss()) {
    const Eigen::Matrix<double, 4, 2> dN = Quad4::derivatives(xi);
    const Eigen::Matrix<double, 3, 2> T = X.transpose() * dN;  // tangents
    out += w * T.col(0).cross(T.col(1)).norm() * Quad4::shape(xi);
  }
  return out;
}

Eigen::Matrix<double, 4, 3> quad_face_area_vectors(const Eigen::Matrix<double, 4, 3>& X) {
  Eigen::Matrix<double, 4, 3> out = Eigen::Matrix<double, 4, 3>::Zero();
  for (const auto& [xi, w] : Quad4::gauss()) {
    const Eigen::Matrix<double, 4, 2> dN = Quad4::derivatives(xi);
    const Eigen::Matrix<double, 3, 2> T = X.transpose() * dN;  // tangents
    out += w * Quad4::shape(xi) * T.col(0).cross(T.col(1)).transpose();
  }
  return out;
}

namespace {
void check_face(const Eigen::MatrixXd& X) {
  if (X.cols() != 3 || (X.rows() != 4 && X.rows() != 6))
    throw std::invalid_argument("a 3D face needs 4 (quadrilateral) or 6 (quadratic triangle) nodes of 3 coordinates");
}
// Calls f(N, tangent_xi x tangent_eta, weight) at the 6-node triangle's quadrature points.
template <class F>
void for_triangle_points(const Eigen::MatrixXd& X, F&& f) {
  Eigen::VectorXd N;
  Eigen::MatrixX2d dN;
  for (const auto& q : fsi::face_quadrature(6)) {
    fsi::face_shape(6, q.xi, q.eta, N, dN);
    const Eigen::Matrix<double, 3, 2> T = X.transpose() * dN;
    f(N, Eigen::Vector3d(T.col(0).cross(T.col(1))), q.weight);
  }
}
}  // namespace

Eigen::VectorXd face_weights(const Eigen::MatrixXd& X) {
  check_face(X);
  if (X.rows() == 4) return quad_face_weights(X);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(6);
  for_triangle_points(X,
                      [&](const Eigen::VectorXd& N, const Eigen::Vector3d& n, double w) { out += w * n.norm() * N; });
  return out;
}

Eigen::MatrixXd face_area_vectors(const Eigen::MatrixXd& X) {
  check_face(X);
  if (X.rows() == 4) return quad_face_area_vectors(X);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(6, 3);
  for_triangle_points(
      X, [&](const Eigen::VectorXd& N, const Eigen::Vector3d& n, double w) { out += w * N * n.transpose(); });
  return out;
}

Eigen::VectorXd face_lumped_weights(const Eigen::MatrixXd& X) {
  check_face(X);
  if (X.rows() == 4) return quad_face_weights(X);
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(6);
  double area = 0;
  for_triangle_points(X, [&](const Eigen::VectorXd& N, const Eigen::Vector3d& n, double w) {
    diagonal += w * n.norm() * N.cwiseProduct(N);
    area += w * n.norm();
  });
  return area / diagonal.sum() * diagonal;
}

}  // namespace fsi::solid
