#include "fsi/common/interface_geometry.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fsi {

bool face_is_triangle(int nodes) {
  switch (nodes) {
    case 3:
    case 6:
      return true;
    case 4:
    case 8:
    case 9:
      return false;
    default:
      throw std::invalid_argument(
          fmt::format("a face of {} nodes (3 or 6: triangle, 4, 8 or 9: quadrilateral)", nodes));
  }
}

namespace {

// 1D quadratic Lagrange functions on the nodes -1, 0, 1 (index 0, 2, 1: gmsh's corner, corner, middle).
void lagrange3(double s, std::array<double, 3>& l, std::array<double, 3>& dl) {
  l = {0.5 * s * (s - 1), 0.5 * s * (s + 1), 1 - s * s};
  dl = {s - 0.5, s + 0.5, -2 * s};
}

}  // namespace

void face_shape(int nodes, double xi, double eta, Eigen::VectorXd& N, Eigen::MatrixX2d& dN) {
  N.resize(nodes);
  dN.resize(nodes, 2);
  switch (nodes) {
    case 3:
      N << 1 - xi - eta, xi, eta;
      dN << -1, -1, 1, 0, 0, 1;
      return;
    case 6: {
      const double l0 = 1 - xi - eta, l1 = xi, l2 = eta;
      N << l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1), 4 * l0 * l1, 4 * l1 * l2, 4 * l2 * l0;
      // dl0 = (-1, -1), dl1 = (1, 0), dl2 = (0, 1)
      dN.row(0) << -(4 * l0 - 1), -(4 * l0 - 1);
      dN.row(1) << 4 * l1 - 1, 0;
      dN.row(2) << 0, 4 * l2 - 1;
      dN.row(3) << 4 * (l0 - l1), -4 * l1;
      dN.row(4) << 4 * l2, 4 * l1;
      dN.row(5) << -4 * l2, 4 * (l0 - l2);
      return;
    }
    case 4: {
      static const double sx[] = {-1, 1, 1, -1}, sy[] = {-1, -1, 1, 1};
      for (int a = 0; a < 4; ++a) {
        N[a] = 0.25 * (1 + sx[a] * xi) * (1 + sy[a] * eta);
        dN(a, 0) = 0.25 * sx[a] * (1 + sy[a] * eta);
        dN(a, 1) = 0.25 * sy[a] * (1 + sx[a] * xi);
      }
      return;
    }
    case 8: {
      static const double sx[] = {-1, 1, 1, -1}, sy[] = {-1, -1, 1, 1};
      for (int a = 0; a < 4; ++a) {
        const double px = 1 + sx[a] * xi, py = 1 + sy[a] * eta, q = sx[a] * xi + sy[a] * eta - 1;
        N[a] = 0.25 * px * py * q;
        dN(a, 0) = 0.25 * sx[a] * py * (q + px);
        dN(a, 1) = 0.25 * sy[a] * px * (q + py);
      }
      // mid-edge nodes: 4 (0,-1), 5 (1,0), 6 (0,1), 7 (-1,0)
      N[4] = 0.5 * (1 - xi * xi) * (1 - eta);
      dN.row(4) << -xi * (1 - eta), -0.5 * (1 - xi * xi);
      N[5] = 0.5 * (1 + xi) * (1 - eta * eta);
      dN.row(5) << 0.5 * (1 - eta * eta), -eta * (1 + xi);
      N[6] = 0.5 * (1 - xi * xi) * (1 + eta);
      dN.row(6) << -xi * (1 + eta), 0.5 * (1 - xi * xi);
      N[7] = 0.5 * (1 - xi) * (1 - eta * eta);
      dN.row(7) << -0.5 * (1 - eta * eta), -eta * (1 - xi);
      return;
    }
    case 9: {
      std::array<double, 3> lx, dlx, ly, dly;
      lagrange3(xi, lx, dlx);
      lagrange3(eta, ly, dly);
      // (i, j) indices into lagrange3's (-1, 1, 0) per node, gmsh order
      static const int ix[] = {0, 1, 1, 0, 2, 1, 2, 0, 2}, iy[] = {0, 0, 1, 1, 0, 2, 1, 2, 2};
      for (int a = 0; a < 9; ++a) {
        N[a] = lx[ix[a]] * ly[iy[a]];
        dN(a, 0) = dlx[ix[a]] * ly[iy[a]];
        dN(a, 1) = lx[ix[a]] * dly[iy[a]];
      }
      return;
    }
    default:
      face_is_triangle(nodes);  // throws
  }
}

const std::vector<FaceQuadraturePoint>& face_quadrature(int nodes) {
  // Dunavant's 7-point rule (degree 5) on the unit triangle, weights scaled to its area 1/2.
  static const std::vector<FaceQuadraturePoint> triangle = [] {
    const double a1 = 0.059715871789770, b1 = 0.470142064105115, w1 = 0.132394152788506 / 2;
    const double a2 = 0.797426985353087, b2 = 0.101286507323456, w2 = 0.125939180544827 / 2;
    return std::vector<FaceQuadraturePoint>{{1.0 / 3, 1.0 / 3, 0.225 / 2},
                                            {a1, b1, w1},
                                            {b1, a1, w1},
                                            {b1, b1, w1},
                                            {a2, b2, w2},
                                            {b2, a2, w2},
                                            {b2, b2, w2}};
  }();
  static const std::vector<FaceQuadraturePoint> quad = [] {
    const double g[] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
    std::vector<FaceQuadraturePoint> q;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) q.push_back({g[i], g[j], w[i] * w[j]});
    return q;
  }();
  return face_is_triangle(nodes) ? triangle : quad;
}

namespace {

Eigen::MatrixXd face_nodes(const Eigen::MatrixXd& x, const InterfaceFace& face) {
  Eigen::MatrixXd xe(static_cast<Eigen::Index>(face.nodes.size()), 3);
  for (std::size_t a = 0; a < face.nodes.size(); ++a) xe.row(static_cast<Eigen::Index>(a)) = x.row(face.nodes[a]);
  return xe;
}

// Projects (xi, eta) onto the reference element.
void clamp_reference(bool triangle, double& xi, double& eta) {
  if (!triangle) {
    xi = std::clamp(xi, -1.0, 1.0), eta = std::clamp(eta, -1.0, 1.0);
    return;
  }
  // Euclidean projection onto the unit triangle.
  if (xi + eta > 1) {
    const double shift = 0.5 * (xi + eta - 1);
    xi -= shift, eta -= shift;
  }
  xi = std::max(xi, 0.0), eta = std::max(eta, 0.0);
  if (xi > 1) xi = 1, eta = 0;
  if (eta > 1) eta = 1, xi = 0;
  if (xi + eta > 1) {  // after clamping one coordinate at 0, the hypotenuse again
    const double shift = 0.5 * (xi + eta - 1);
    xi -= shift, eta -= shift;
  }
}

// Closest point of the triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5);
// returns the barycentric (v, w) of b and c.
std::pair<double, double> closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                              const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {0, 0};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {d1 / (d1 - d3), 0};
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {0, d2 / (d2 - d6)};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {1 - w, w};
  }
  const double denom = 1 / (va + vb + vc);
  return {vb * denom, vc * denom};
}

}  // namespace

Eigen::Vector3d face_point(const Eigen::MatrixXd& x, const InterfaceFace& face, double xi, double eta) {
  Eigen::VectorXd N;
  Eigen::MatrixX2d dN;
  face_shape(static_cast<int>(face.nodes.size()), xi, eta, N, dN);
  return face_nodes(x, face).transpose() * N;
}

double face_area(const Eigen::MatrixXd& x, const InterfaceFace& face) {
  const int nodes = static_cast<int>(face.nodes.size());
  const Eigen::MatrixXd xe = face_nodes(x, face);
  Eigen::VectorXd N;
  Eigen::MatrixX2d dN;
  double area = 0;
  for (const auto& q : face_quadrature(nodes)) {
    face_shape(nodes, q.xi, q.eta, N, dN);
    const Eigen::Matrix<double, 3, 2> J = xe.transpose() * dN;
    area += q.weight * J.col(0).cross(J.col(1)).norm();
  }
  return area;
}

FaceProjection project_on_face(const Eigen::MatrixXd& x, const InterfaceFace& face, const Eigen::Vector3d& p) {
  const int nodes = static_cast<int>(face.nodes.size());
  const bool triangle = face_is_triangle(nodes);
  FaceProjection out;
  if (nodes == 3) {
    const Eigen::Vector3d a = x.row(face.nodes[0]).transpose(), b = x.row(face.nodes[1]).transpose(),
                          c = x.row(face.nodes[2]).transpose();
    const auto [v, w] = closest_on_triangle(p, a, b, c);
    out.xi = v, out.eta = w;
    out.point = a + v * (b - a) + w * (c - a);
    out.distance = (out.point - p).norm();
    return out;
  }
  const Eigen::MatrixXd xe = face_nodes(x, face);
  Eigen::VectorXd N;
  Eigen::MatrixX2d dN;
  double xi = triangle ? 1.0 / 3 : 0.0, eta = xi;
  const double size = (xe.colwise().maxCoeff() - xe.colwise().minCoeff()).norm();
  for (int it = 0; it < 50; ++it) {
    face_shape(nodes, xi, eta, N, dN);
    const Eigen::Vector3d r = xe.transpose() * N - p;
    const Eigen::Matrix<double, 3, 2> J = xe.transpose() * dN;
    const Eigen::Matrix2d JtJ = J.transpose() * J;
    const Eigen::Vector2d step = JtJ.ldlt().solve(-J.transpose() * r);
    double nxi = xi + step[0], neta = eta + step[1];
    clamp_reference(triangle, nxi, neta);
    const double moved = std::abs(nxi - xi) + std::abs(neta - eta);
    xi = nxi, eta = neta;
    if (moved < 1e-15 * (1 + size)) break;
  }
  face_shape(nodes, xi, eta, N, dN);
  out.xi = xi, out.eta = eta;
  out.point = xe.transpose() * N;
  out.distance = (out.point - p).norm();
  return out;
}

Eigen::MatrixXd interface_positions(const InterfaceMeshData& mesh, const Eigen::VectorXd& displacement) {
  Eigen::MatrixXd x = mesh.coordinates;
  const Eigen::Index n = x.rows(), d = x.cols();
  if (displacement.size() == d * n)
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index c = 0; c < d; ++c) x(i, c) += displacement[d * i + c];
  return x;
}

NodalMatrix nodal_interface_mass(const InterfaceMeshData& mesh, const Eigen::VectorXd& displacement) {
  const Eigen::Index n = mesh.coordinates.rows();
  std::vector<Eigen::Triplet<double>> t;
  if (mesh.points_only()) {
    for (Eigen::Index i = 0; i < n; ++i) t.emplace_back(i, i, mesh.lumped_measure[i]);
  } else if (mesh.dimension == 2) {
    auto x = [&](int i) {
      Eigen::Vector2d p = mesh.coordinates.row(i).transpose();
      if (displacement.size() == 2 * n) p += displacement.segment<2>(2 * i);
      return p;
    };
    for (const auto& seg : mesh.segments) {
      const double len = (x(seg[1]) - x(seg[0])).norm();
      t.emplace_back(seg[0], seg[0], len / 3);
      t.emplace_back(seg[1], seg[1], len / 3);
      t.emplace_back(seg[0], seg[1], len / 6);
      t.emplace_back(seg[1], seg[0], len / 6);
    }
  } else {
    const Eigen::MatrixXd x = interface_positions(mesh, displacement);
    Eigen::VectorXd N;
    Eigen::MatrixX2d dN;
    for (const auto& face : mesh.faces) {
      const int nodes = static_cast<int>(face.nodes.size());
      const Eigen::MatrixXd xe = face_nodes(x, face);
      Eigen::MatrixXd me = Eigen::MatrixXd::Zero(nodes, nodes);
      for (const auto& q : face_quadrature(nodes)) {
        face_shape(nodes, q.xi, q.eta, N, dN);
        const Eigen::Matrix<double, 3, 2> J = xe.transpose() * dN;
        me += q.weight * J.col(0).cross(J.col(1)).norm() * N * N.transpose();
      }
      for (int a = 0; a < nodes; ++a)
        for (int b = 0; b < nodes; ++b) t.emplace_back(face.nodes[a], face.nodes[b], me(a, b));
    }
  }
  NodalMatrix m(n, n);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

Eigen::VectorXd lumped_interface_measure(const InterfaceMeshData& mesh) {
  if (mesh.points_only()) return mesh.lumped_measure;
  const NodalMatrix m = nodal_interface_mass(mesh, Eigen::VectorXd());
  return m * Eigen::VectorXd::Ones(m.cols());
}

InterfaceMeshData rectangle_surface(const Eigen::Vector3d& c, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2,
                                    double a, double b, int n1, int n2, bool triangles) {
  if (n1 < 1 || n2 < 1) throw std::invalid_argument(fmt::format("a surface of {} x {} divisions", n1, n2));
  InterfaceMeshData mesh;
  mesh.dimension = 3;
  const int nodes = (n1 + 1) * (n2 + 1);
  mesh.coordinates.resize(nodes, 3);
  auto id = [&](int i, int j) { return j * (n1 + 1) + i; };
  for (int j = 0; j <= n2; ++j)
    for (int i = 0; i <= n1; ++i)
      mesh.coordinates.row(id(i, j)) =
          (c + (a * (static_cast<double>(i) / n1 - 0.5)) * e1 + (b * (static_cast<double>(j) / n2 - 0.5)) * e2)
              .transpose();
  for (int j = 0; j < n2; ++j)
    for (int i = 0; i < n1; ++i) {
      const int p0 = id(i, j), p1 = id(i + 1, j), p2 = id(i + 1, j + 1), p3 = id(i, j + 1);
      if (triangles) {
        mesh.faces.push_back({{p0, p1, p2}});
        mesh.faces.push_back({{p0, p2, p3}});
      } else {
        mesh.faces.push_back({{p0, p1, p2, p3}});
      }
    }
  for (int i = 0; i < nodes; ++i) mesh.node_ids.push_back(i);
  mesh.lumped_measure = lumped_interface_measure(mesh);
  return mesh;
}

}  // namespace fsi
