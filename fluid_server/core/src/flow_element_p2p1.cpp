// The isoparametric Taylor-Hood P2/P1 element part of FlowSolver (flow_element.hpp): 6-node
// triangles, (u, v) of every node at 2 i, 2 i + 1, then p of the vertices (2 n + i); P2
// traces on the interface edges (4-point Gauss), every edge split at its midpoint for the
// coupler.
#include <fmt/format.h>

#include <Eigen/LU>
#include <stdexcept>

#include "flow_element.hpp"
#include "fsi/fluid/p2p1_element.hpp"
#include "nitsche_trace.hpp"

namespace fsi::fluid::detail {
namespace {

constexpr int kEdgeNodes[3][3] = {{0, 1, 3}, {1, 2, 4}, {2, 0, 5}};
const Eigen::Vector2d kRefVertex[3] = {{0, 0}, {1, 0}, {0, 1}};
// 4-point Gauss-Legendre on [0, 1].
constexpr double kGaussX[4] = {0.0694318442029737, 0.3300094782075719, 0.6699905217924281, 0.9305681557970263};
constexpr double kGaussW[4] = {0.1739274225687269, 0.3260725774312731, 0.3260725774312731, 0.1739274225687269};

using EdgePoint = TracePoint<6, 2>;

// Geometry at point s of edge k of an element: shape functions, physical gradients, the
// length element and the outward normal.
EdgePoint edge_point(const Eigen::Matrix<double, 6, 2>& x, int k, double s) {
  EdgePoint p;
  const Eigen::Vector2d d = kRefVertex[(k + 1) % 3] - kRefVertex[k];
  const Eigen::Vector2d r = kRefVertex[k] + s * d;
  Eigen::Matrix<double, 6, 2> dN;
  p2_shape(r.x(), r.y(), p.N, dN);
  const Eigen::Matrix2d J = x.transpose() * dN;
  p.G = dN * J.inverse();
  const Eigen::Vector2d t = J * d;
  p.ds = t.norm();
  p.normal = Eigen::Vector2d(t.y(), -t.x()) / p.ds;  // counter-clockwise element: outward
  p.L << 1 - r.x() - r.y(), r.x(), r.y();
  return p;
}

class P2P1Element final : public FlowElement {
 public:
  explicit P2P1Element(FluidMesh mesh) : mesh_(mesh.quadratic() ? std::move(mesh) : mesh.quadratic_from_linear()) {
    // Curved elements must map validly before anything moves.
    for (int e = 0; e < mesh_.triangle_count(); ++e) {
      const auto x = element_positions(mesh_.nodes, e);
      if (!(p2_min_jacobian(x) > 0)) {
        const Eigen::RowVector2d c = (x.row(0) + x.row(1) + x.row(2)) / 3.0;
        throw std::invalid_argument(
            fmt::format("fluid mesh: 6-node triangle {} near ({:.5g}, {:.5g}) is inverted or "
                        "too strongly curved (det J <= 0 inside)",
                        e, c(0), c(1)));
      }
    }
  }
  const char* name() const override { return "p2p1"; }
  const FluidMesh& mesh() const override { return mesh_; }
  DofLayout layout() const override {
    const int n = mesh_.node_count();
    return {2 * n + mesh_.vertices(), 2, 2 * n, 1};
  }
  int local_size() const override { return 15; }
  void element_dofs(int e, int* dofs) const override {
    const auto nodes = mesh_.element_nodes6(e);
    for (int k = 0; k < 6; ++k) {
      dofs[2 * k] = 2 * nodes(k);
      dofs[2 * k + 1] = 2 * nodes(k) + 1;
    }
    for (int k = 0; k < 3; ++k) dofs[12 + k] = 2 * mesh_.node_count() + nodes(k);
  }
  bool damped_newton() const override { return true; }

  bool assemble(int e, const AssemblyInput& a, LocalSystem& local, double& bad) const override {
    P2ElementInput in;
    in.density = a.params.density;
    in.viscosity = a.params.viscosity;
    in.alpha0_dt = a.alpha0_dt;
    in.dt = a.dt;
    in.newton = a.params.newton;
    const auto nodes = mesh_.element_nodes6(e);
    for (int k = 0; k < 6; ++k) {
      const int node = nodes(k);
      in.x.row(k) = a.X.row(node);
      for (int c = 0; c < 2; ++c) {
        in.velocity(k, c) = a.U_lin(2 * node + c);
        in.advection(k, c) = a.U_lin(2 * node + c) - a.mesh_velocity(node, c);
        in.history(k, c) = a.history(2 * node + c);
      }
      in.force.row(k) = a.body.row(node);
    }
    P2ElementOutput out;
    if (!assemble_p2p1_element(in, a.params.stabilisation, out)) {
      bad = out.min_jacobian;
      return false;
    }
    local.matrix = out.matrix;
    local.rhs = out.rhs;
    return true;
  }
  const char* cell_name() const override { return "6-node element"; }
  std::string inverted(double det) const override {
    return fmt::format("inverted or too strongly curved (det J = {:.3g})", det);
  }

  InterfaceEdge interface_edge(int e, int k, int, int, const std::map<int, int>& iface,
                               std::vector<std::array<int, 2>>& segments) const override {
    InterfaceEdge edge{};
    edge.element = e;
    edge.edge = k;
    const auto nodes = mesh_.element_nodes6(e);
    for (int j = 0; j < 3; ++j) {
      edge.local[static_cast<std::size_t>(j)] = kEdgeNodes[k][j];
      edge.iface[static_cast<std::size_t>(j)] = iface.at(nodes(kEdgeNodes[k][j]));
    }
    segments.push_back({edge.iface[0], edge.iface[2]});
    segments.push_back({edge.iface[2], edge.iface[1]});
    return edge;
  }

  // The seed paper's fluid weak form with P2 traces.
  void nitsche(const InterfaceEdge& edge, const NitscheInput& in, LocalSystem& out) const override {
    const auto x = element_positions(in.X, edge.element);
    Eigen::Matrix<double, 6, 2> vs = Eigen::Matrix<double, 6, 2>::Zero();
    for (std::size_t j = 0; j < 3; ++j) vs.row(edge.local[j]) = in.v_s.segment<2>(2 * edge.iface[j]).transpose();
    out.matrix.setZero(15, 15);
    out.rhs.setZero(15);
    const bool step_start = in.params.penalty_on_step_start;
    const auto x_pen = step_start ? element_positions(in.X_n, edge.element) : x;  // the penalty term's geometry
    for (int g = 0; g < 4; ++g) {
      const auto p = edge_point(x, edge.edge, kGaussX[g]);
      const double w = kGaussW[g] * p.ds;
      const double w_pen = step_start ? kGaussW[g] * edge_point(x_pen, edge.edge, kGaussX[g]).ds : w;
      add_nitsche_point(p, w, w_pen, vs, in.params, out);
    }
  }

  void pressure_load(const InterfaceEdge& edge, const Eigen::MatrixX2d& X, double p,
                     Eigen::VectorXd& load) const override {
    const auto x = element_positions(X, edge.element);
    load.setZero(15);
    for (int g = 0; g < 4; ++g) {
      const auto q = edge_point(x, edge.edge, kGaussX[g]);
      for (int i = 0; i < 6; ++i)
        for (int c = 0; c < 2; ++c) load(2 * i + c) -= p * kGaussW[g] * q.ds * q.N(i) * q.normal(c);
    }
  }

  void interface_mass(const InterfaceEdge& edge, const Eigen::MatrixX2d& X,
                      std::vector<Eigen::Triplet<double>>& t) const override {
    const auto x = element_positions(X, edge.element);
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    for (int g = 0; g < 4; ++g) {
      const auto p = edge_point(x, edge.edge, kGaussX[g]);
      for (std::size_t i = 0; i < 3; ++i)
        for (std::size_t j = 0; j < 3; ++j) m(i, j) += kGaussW[g] * p.ds * p.N(edge.local[i]) * p.N(edge.local[j]);
    }
    for (std::size_t i = 0; i < 3; ++i)
      for (std::size_t j = 0; j < 3; ++j) t.emplace_back(edge.iface[i], edge.iface[j], m(i, j));
  }

  // Linear between the vertices.
  Eigen::VectorXd nodal_pressure(const Eigen::VectorXd& U) const override {
    const int n = mesh_.node_count();
    Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < mesh_.vertices(); ++i) p(i) = U(2 * n + i);
    mesh_.interpolate_midpoints(p);
    return p;
  }
  Eigen::Vector2d velocity_at(int e, const Eigen::Vector3d& l, const Eigen::VectorXd& U) const override {
    Eigen::Matrix<double, 6, 1> N;
    Eigen::Matrix<double, 6, 2> dN;
    p2_shape(l(1), l(2), N, dN);
    const auto nodes = mesh_.element_nodes6(e);
    Eigen::Vector2d v = Eigen::Vector2d::Zero();
    for (int k = 0; k < 6; ++k) v += N(k) * U.segment<2>(2 * nodes(k));
    return v;
  }

 private:
  FluidMesh mesh_;
  Eigen::Matrix<double, 6, 2> element_positions(const Eigen::MatrixX2d& X, int e) const {
    Eigen::Matrix<double, 6, 2> x;
    const auto nodes = mesh_.element_nodes6(e);
    for (int k = 0; k < 6; ++k) x.row(k) = X.row(nodes(k));
    return x;
  }
};

}  // namespace

std::unique_ptr<FlowElement> make_p2p1_element(FluidMesh mesh) {
  return std::make_unique<P2P1Element>(std::move(mesh));
}

}  // namespace fsi::fluid::detail
