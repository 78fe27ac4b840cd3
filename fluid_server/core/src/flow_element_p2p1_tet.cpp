// The isoparametric Taylor-Hood P2/P1 element part of the 3D FlowSolver (flow_element.hpp):
// 10-node tetrahedra, (u, v, w) of every node at 3 i .. 3 i + 2, then p of the vertices
// (3 n + i). P2 traces on the interface faces (6-node triangles), integrated with the 7-point
// rule exact to degree 5 (fsi::face_quadrature).
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <stdexcept>

#include "flow_element.hpp"
#include "fsi/common/interface_geometry.hpp"
#include "fsi/fluid/p2p1_tet_element.hpp"
#include "nitsche_trace.hpp"

namespace fsi::fluid::detail {
namespace {

const Eigen::Vector3d kRefVertex[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
using FacePoint = TracePoint<10, 3>;

// The local node (4 .. 9) of the midpoint of the tetrahedron's edge between local vertices a, b.
int midpoint_node(int a, int b) {
  for (int k = 0; k < 6; ++k)
    if ((kTetEdges[k][0] == a && kTetEdges[k][1] == b) || (kTetEdges[k][0] == b && kTetEdges[k][1] == a)) return 4 + k;
  throw std::logic_error("not an edge of a tetrahedron");
}

// Geometry at the point (xi, eta) of the interface face (local vertices face.local[0..2],
// xi along 0 -> 1, eta along 0 -> 2) of an element at positions x: shape functions, physical
// gradients, the area element (per unit reference area) and the normal pointing away from the
// vertex opposite the face (face.edge), i.e. out of the fluid.
FacePoint face_point(const Eigen::Matrix<double, 10, 3>& x, const InterfaceEdge& face, double xi, double eta) {
  FacePoint p;
  const Eigen::Vector3d& r0 = kRefVertex[face.local[0]];
  const Eigen::Vector3d d1 = kRefVertex[face.local[1]] - r0, d2 = kRefVertex[face.local[2]] - r0;
  const Eigen::Vector3d r = r0 + xi * d1 + eta * d2;
  Eigen::Matrix<double, 10, 3> dN;
  p2_tet_shape(r.x(), r.y(), r.z(), p.N, dN);
  const Eigen::Matrix3d J = x.transpose() * dN;
  p.G = dN * J.inverse();
  const Eigen::Vector3d t1 = J * d1, t2 = J * d2;
  const Eigen::Vector3d n = t1.cross(t2);
  p.ds = n.norm();
  p.normal = n / p.ds;
  const Eigen::Vector3d X = x.transpose() * p.N;
  if (p.normal.dot(X - x.row(face.edge).transpose()) < 0) p.normal = -p.normal;
  p.L << 1 - r.x() - r.y() - r.z(), r.x(), r.y(), r.z();
  return p;
}

class P2P1TetElement final : public FlowElementT<3> {
 public:
  explicit P2P1TetElement(TetMesh mesh) : mesh_(mesh.quadratic() ? std::move(mesh) : mesh.quadratic_from_linear()) {
    for (int e = 0; e < mesh_.cell_count(); ++e) {
      const auto x = element_positions(mesh_.nodes, e);
      if (!(p2_tet_min_jacobian(x) > 0)) {
        const Eigen::RowVector3d c = x.topRows<4>().colwise().mean();
        throw std::invalid_argument(
            fmt::format("fluid mesh: 10-node tetrahedron {} near ({:.5g}, {:.5g}, {:.5g}) is inverted or too "
                        "strongly curved (det J <= 0 inside)",
                        e, c(0), c(1), c(2)));
      }
    }
  }
  const char* name() const override { return "p2p1"; }
  const TetMesh& mesh() const override { return mesh_; }
  DofLayout layout() const override {
    const int n = mesh_.node_count();
    return {3 * n + mesh_.vertices(), 3, 3 * n, 1};
  }
  int local_size() const override { return 34; }
  void element_dofs(int e, int* dofs) const override {
    const auto nodes = mesh_.element_nodes10(e);
    for (int k = 0; k < 10; ++k)
      for (int c = 0; c < 3; ++c) dofs[3 * k + c] = 3 * nodes(k) + c;
    for (int k = 0; k < 4; ++k) dofs[30 + k] = 3 * mesh_.node_count() + nodes(k);
  }
  bool damped_newton() const override { return true; }

  bool assemble(int e, const AssemblyInput& a, LocalSystem& local, double& bad) const override {
    P2TetInput in;
    in.density = a.params.density;
    in.viscosity = a.params.viscosity;
    in.alpha0_dt = a.alpha0_dt;
    in.newton = a.params.newton;
    in.grad_div = a.params.stabilisation.grad_div;
    const auto nodes = mesh_.element_nodes10(e);
    for (int k = 0; k < 10; ++k) {
      const int node = nodes(k);
      in.x.row(k) = a.X.row(node);
      for (int c = 0; c < 3; ++c) {
        in.velocity(k, c) = a.U_lin(3 * node + c);
        in.advection(k, c) = a.U_lin(3 * node + c) - a.mesh_velocity(node, c);
        in.history(k, c) = a.history(3 * node + c);
      }
      in.force.row(k) = a.body.row(node);
    }
    P2TetOutput out;
    if (!assemble_p2p1_tet(in, out)) {
      bad = out.min_jacobian;
      return false;
    }
    local.matrix = out.matrix;
    local.rhs = out.rhs;
    return true;
  }
  const char* cell_name() const override { return "10-node tetrahedron"; }
  std::string inverted(double det) const override {
    return fmt::format("inverted or too strongly curved (det J = {:.3g})", det);
  }

  InterfaceEdge interface_edge(int, int, int, int, const std::map<int, int>&,
                               std::vector<std::array<int, 2>>&) const override {
    throw std::logic_error("the 3D fluid's interface is made of faces");
  }
  InterfaceEdge interface_face(int e, int opposite, const std::array<int, 3>& abc, const std::map<int, int>& iface,
                               std::vector<std::array<int, 6>>& faces) const override {
    InterfaceEdge face{};
    face.element = e;
    face.edge = opposite;
    for (std::size_t j = 0; j < 3; ++j)
      for (int k = 0; k < 4; ++k)
        if (mesh_.tets(e, k) == abc[j]) face.local[j] = k;
    for (std::size_t j = 0; j < 3; ++j) face.local[3 + j] = midpoint_node(face.local[j], face.local[(j + 1) % 3]);
    const auto nodes = mesh_.element_nodes10(e);
    for (std::size_t j = 0; j < 6; ++j) face.iface[j] = iface.at(nodes(face.local[j]));
    faces.push_back(face.iface);
    return face;
  }

  // The seed paper's fluid weak form with P2 traces on the face.
  void nitsche(const InterfaceEdge& face, const NitscheInput& in, LocalSystem& out) const override {
    const auto x = element_positions(in.X, face.element);
    Eigen::Matrix<double, 10, 3> vs = Eigen::Matrix<double, 10, 3>::Zero();
    for (std::size_t j = 0; j < 6; ++j) vs.row(face.local[j]) = in.v_s.segment<3>(3 * face.iface[j]).transpose();
    out.matrix.setZero(34, 34);
    out.rhs.setZero(34);
    const bool step_start = in.params.penalty_on_step_start;
    const auto x_pen = step_start ? element_positions(in.X_n, face.element) : x;
    for (const auto& q : fsi::face_quadrature(6)) {
      const auto p = face_point(x, face, q.xi, q.eta);
      const double w = q.weight * p.ds;
      const double w_pen = step_start ? q.weight * face_point(x_pen, face, q.xi, q.eta).ds : w;
      add_nitsche_point(p, w, w_pen, vs, in.params, out);
    }
  }
  void pressure_load(const InterfaceEdge& face, const NodeMatrix<3>& X, double p,
                     Eigen::VectorXd& load) const override {
    const auto x = element_positions(X, face.element);
    load.setZero(34);
    for (const auto& q : fsi::face_quadrature(6)) {
      const auto fp = face_point(x, face, q.xi, q.eta);
      for (int i = 0; i < 10; ++i)
        for (int c = 0; c < 3; ++c) load(3 * i + c) -= p * q.weight * fp.ds * fp.N(i) * fp.normal(c);
    }
  }
  void backflow(const InterfaceEdge& face, const NodeMatrix<3>& X, const Eigen::VectorXd& U_lin,
                const NodeMatrix<3>& mesh_velocity, double coefficient, LocalSystem& out) const override {
    const auto x = element_positions(X, face.element);
    const auto w = element_positions(mesh_velocity, face.element);
    const auto nodes = mesh_.element_nodes10(face.element);
    Eigen::Matrix<double, 10, 3> u;
    for (int k = 0; k < 10; ++k) u.row(k) = U_lin.segment<3>(3 * nodes(k)).transpose();
    out.matrix.setZero(34, 34);
    out.rhs.setZero(34);
    for (const auto& q : fsi::face_quadrature(6)) {
      const auto p = face_point(x, face, q.xi, q.eta);
      const double flux = ((u - w).transpose() * p.N).dot(p.normal);
      if (flux >= 0) continue;
      const double a = -coefficient * flux * q.weight * p.ds;
      for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 10; ++j)
          for (int c = 0; c < 3; ++c) out.matrix(3 * i + c, 3 * j + c) += a * p.N(i) * p.N(j);
    }
  }
  void interface_mass(const InterfaceEdge& face, const NodeMatrix<3>& X,
                      std::vector<Eigen::Triplet<double>>& t) const override {
    const auto x = element_positions(X, face.element);
    Eigen::Matrix<double, 6, 6> m = Eigen::Matrix<double, 6, 6>::Zero();
    for (const auto& q : fsi::face_quadrature(6)) {
      const auto p = face_point(x, face, q.xi, q.eta);
      for (std::size_t i = 0; i < 6; ++i)
        for (std::size_t j = 0; j < 6; ++j)
          m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) +=
              q.weight * p.ds * p.N(face.local[i]) * p.N(face.local[j]);
    }
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t j = 0; j < 6; ++j)
        t.emplace_back(face.iface[i], face.iface[j], m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)));
  }

  Eigen::VectorXd nodal_pressure(const Eigen::VectorXd& U) const override {
    const int n = mesh_.node_count();
    Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < mesh_.vertices(); ++i) p(i) = U(3 * n + i);
    mesh_.interpolate_midpoints(p);
    return p;
  }
  Point<3> velocity_at(int e, const Eigen::Vector4d& l, const Eigen::VectorXd& U) const override {
    Eigen::Matrix<double, 10, 1> N;
    Eigen::Matrix<double, 10, 3> dN;
    p2_tet_shape(l(1), l(2), l(3), N, dN);
    const auto nodes = mesh_.element_nodes10(e);
    Point<3> v = Point<3>::Zero();
    for (int k = 0; k < 10; ++k) v += N(k) * U.segment<3>(3 * nodes(k));
    return v;
  }

 private:
  TetMesh mesh_;
  Eigen::Matrix<double, 10, 3> element_positions(const Eigen::MatrixX3d& X, int e) const {
    Eigen::Matrix<double, 10, 3> x;
    const auto nodes = mesh_.element_nodes10(e);
    for (int k = 0; k < 10; ++k) x.row(k) = X.row(nodes(k));
    return x;
  }
};

}  // namespace

std::unique_ptr<FlowElementT<3>> make_p2p1_tet_element(TetMesh mesh) {
  return std::make_unique<P2P1TetElement>(std::move(mesh));
}

}  // namespace fsi::fluid::detail
