// The isoparametric Taylor-Hood P2/P1 element part of the 3D FlowSolver (flow_element.hpp):
// 10-node tetrahedra, (u, v, w) of every node at 3 i .. 3 i + 2, then p of the vertices
// (3 n + i). No Nitsche interface yet (FlowSolver3 refuses interface groups).
#include <fmt/format.h>

#include <stdexcept>

#include "flow_element.hpp"
#include "fsi/fluid/p2p1_tet_element.hpp"

namespace fsi::fluid::detail {
namespace {

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
    throw std::invalid_argument("the 3D fluid has no Nitsche interface yet");
  }
  void nitsche(const InterfaceEdge&, const NitscheInput&, LocalSystem&) const override {
    throw std::invalid_argument("the 3D fluid has no Nitsche interface yet");
  }
  void interface_mass(const InterfaceEdge&, const NodeMatrix<3>&, std::vector<Eigen::Triplet<double>>&) const override {
    throw std::invalid_argument("the 3D fluid has no Nitsche interface yet");
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
