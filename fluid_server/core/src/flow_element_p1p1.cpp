// The P1/P1 SUPG/PSPG/LSIC element part of FlowSolver (flow_element.hpp): 3-node triangles,
// unknowns (u, v, p) interleaved per node, linear traces on the interface segments.
#include <fmt/format.h>

#include <stdexcept>

#include "flow_element.hpp"
#include "fsi/fluid/p1_element.hpp"

namespace fsi::fluid::detail {
namespace {

// div(mu grad u) per element (rows: triangles; constant in each), from the nodal gradients of
// the P1 velocity u (interleaved u, v, p) by lumped L2 projection:
// G_i = sum_e |e|/3 grad u_e / sum_e |e|/3. Degenerate elements get 0 (the assembly reports them).
Eigen::MatrixX2d element_viscous_term(const FluidMesh& mesh, const Eigen::MatrixX2d& X, const Eigen::VectorXd& u,
                                      double mu) {
  const int n = mesh.node_count(), ne = mesh.triangle_count();
  Eigen::MatrixXd grad = Eigen::MatrixXd::Zero(n, 4);  // du/dx, du/dy, dv/dx, dv/dy
  Eigen::VectorXd lumped = Eigen::VectorXd::Zero(n);
  std::vector<TriangleGeometry> geo(static_cast<std::size_t>(ne));
  for (int e = 0; e < ne; ++e) {
    Eigen::Matrix<double, 3, 2> x;
    for (int k = 0; k < 3; ++k) x.row(k) = X.row(mesh.triangles(e, k));
    const auto& g = geo[static_cast<std::size_t>(e)] = triangle_geometry(x);
    if (!(g.area > 0)) continue;
    Eigen::Matrix2d gu = Eigen::Matrix2d::Zero();  // row c: grad of component c
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 2; ++c) gu.row(c) += u(3 * mesh.triangles(e, k) + c) * g.grad.row(k);
    for (int k = 0; k < 3; ++k) {
      const int node = mesh.triangles(e, k);
      lumped(node) += g.area / 3.0;
      grad.row(node) += g.area / 3.0 * Eigen::RowVector4d(gu(0, 0), gu(0, 1), gu(1, 0), gu(1, 1));
    }
  }
  for (int i = 0; i < n; ++i)
    if (lumped(i) > 0) grad.row(i) /= lumped(i);
  Eigen::MatrixX2d out = Eigen::MatrixX2d::Zero(ne, 2);
  for (int e = 0; e < ne; ++e) {
    const auto& g = geo[static_cast<std::size_t>(e)];
    if (!(g.area > 0)) continue;
    for (int k = 0; k < 3; ++k) {
      const int node = mesh.triangles(e, k);
      out(e, 0) += grad(node, 0) * g.grad(k, 0) + grad(node, 1) * g.grad(k, 1);
      out(e, 1) += grad(node, 2) * g.grad(k, 0) + grad(node, 3) * g.grad(k, 1);
    }
  }
  return mu * out;
}

class P1P1Element final : public FlowElement {
 public:
  explicit P1P1Element(FluidMesh mesh) : mesh_(std::move(mesh)) {
    if (mesh_.quadratic())
      throw std::invalid_argument(
          "the P1/P1 fluid needs a mesh of 3-node triangles (this one has 6-node triangles: "
          "use fluid.element: p2p1, or mesh with -order 1)");
  }
  const char* name() const override { return "p1p1"; }
  const FluidMesh& mesh() const override { return mesh_; }
  DofLayout layout() const override { return {3 * mesh_.node_count(), 3, 2, 3}; }
  int local_size() const override { return 9; }
  void element_dofs(int e, int* dofs) const override {
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) dofs[3 * k + c] = 3 * mesh_.triangles(e, k) + c;
  }
  bool damped_newton() const override { return false; }

  // The reconstructed viscous residual div(mu grad u*) per element (element_viscous_term).
  void prepare(const AssemblyInput& in) override {
    const auto& stab = in.params.stabilisation;
    reconstruct_ = stab.viscous_residual && (stab.supg || stab.pspg);
    if (reconstruct_) element_viscous_ = element_viscous_term(mesh_, in.X, in.U_lin, in.params.viscosity);
  }

  bool assemble(int e, const AssemblyInput& a, LocalSystem& local, double& bad) const override {
    ElementInput in;
    in.density = a.params.density;
    in.viscosity = a.params.viscosity;
    in.alpha0_dt = a.alpha0_dt;
    in.dt = a.dt;
    in.newton = a.params.newton;
    for (int k = 0; k < 3; ++k) {
      const int node = mesh_.triangles(e, k);
      in.x.row(k) = a.X.row(node);
      in.velocity(k, 0) = a.U_lin(3 * node);
      in.velocity(k, 1) = a.U_lin(3 * node + 1);
      in.advection(k, 0) = a.U_lin(3 * node) - a.mesh_velocity(node, 0);
      in.advection(k, 1) = a.U_lin(3 * node + 1) - a.mesh_velocity(node, 1);
      in.history(k, 0) = a.history(3 * node);
      in.history(k, 1) = a.history(3 * node + 1);
      in.force.row(k) = a.body.row(node);
    }
    if (reconstruct_) in.viscous = element_viscous_.row(e);
    const double area = triangle_geometry(in.x).area;
    if (!(area > 0)) {
      bad = area;
      return false;
    }
    ElementOutput out;
    assemble_element(in, a.params.stabilisation, out);
    local.matrix = out.matrix;
    local.rhs = out.rhs;
    return true;
  }
  const char* cell_name() const override { return "element"; }
  std::string inverted(double area) const override { return fmt::format("inverted or degenerate (area {:.3g})", area); }

  InterfaceEdge interface_edge(int e, int k, int a, int b, const std::map<int, int>& iface,
                               std::vector<std::array<int, 2>>& segments) const override {
    InterfaceEdge edge{};
    edge.element = e;
    edge.edge = k;
    for (int j = 0; j < 3; ++j) {
      if (mesh_.triangles(e, j) == a) edge.local[0] = j;
      if (mesh_.triangles(e, j) == b) edge.local[1] = j;
    }
    edge.iface[0] = iface.at(a);
    edge.iface[1] = iface.at(b);
    segments.push_back({edge.iface[0], edge.iface[1]});
    return edge;
  }

  // The seed paper's fluid weak form, pseudo-stress sigma = mu grad v - p I.
  void nitsche(const InterfaceEdge& s, const NitscheInput& in, LocalSystem& out) const override {
    const double g1 = in.params.nitsche_penalty, g2 = in.params.nitsche_symmetry, mu = in.params.viscosity;
    const int la = s.local[0], lb = s.local[1];
    Eigen::Matrix<double, 3, 2> x;
    for (int k = 0; k < 3; ++k) x.row(k) = in.X.row(mesh_.triangles(s.element, k));
    const auto geo = triangle_geometry(x);
    const Eigen::Vector2d xa = x.row(la).transpose(), xb = x.row(lb).transpose();
    const double length = (xb - xa).norm();
    Eigen::Vector2d normal((xb - xa).y(), -(xb - xa).x());
    normal /= length;
    const int third = 3 - la - lb;
    if (normal.dot(x.row(third).transpose() - xa) > 0) normal = -normal;  // outward of the fluid
    Eigen::Matrix3d mass = Eigen::Matrix3d::Zero();                       // int_seg N_i N_j
    Eigen::Vector3d integral = Eigen::Vector3d::Zero();
    mass(la, la) = mass(lb, lb) = length / 3.0;
    mass(la, lb) = mass(lb, la) = length / 6.0;
    integral(la) = integral(lb) = length / 2.0;
    // The penalty term's mass: on this interface, or on the last accepted step's.
    Eigen::Matrix3d penalty_mass = mass;
    if (in.params.penalty_on_step_start) {
      const double ln =
          (in.X_n.row(mesh_.triangles(s.element, lb)) - in.X_n.row(mesh_.triangles(s.element, la))).norm();
      penalty_mass = mass * (ln / length);
    }
    const Eigen::Vector3d gn = geo.grad * normal;  // grad N_i . n
    Eigen::Matrix<double, 3, 2> vs = Eigen::Matrix<double, 3, 2>::Zero();
    vs.row(la) = in.v_s.segment<2>(2 * s.iface[0]).transpose();
    vs.row(lb) = in.v_s.segment<2>(2 * s.iface[1]).transpose();
    const Eigen::Matrix<double, 3, 2> mass_vs = mass * vs, penalty_vs = penalty_mass * vs;
    const Eigen::RowVector2d int_vs = integral.transpose() * vs;
    out.matrix.setZero(9, 9);
    out.rhs.setZero(9);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        const double vel = g1 * penalty_mass(i, j) - mu * integral(i) * gn(j) - g2 * mu * gn(i) * integral(j);
        for (int c = 0; c < 2; ++c) {
          out.matrix(3 * i + c, 3 * j + c) += vel;
          out.matrix(3 * i + c, 3 * j + 2) += normal(c) * mass(i, j);
          out.matrix(3 * i + 2, 3 * j + c) += g2 * normal(c) * mass(i, j);
        }
      }
      for (int c = 0; c < 2; ++c) out.rhs(3 * i + c) = g1 * penalty_vs(i, c) - g2 * mu * gn(i) * int_vs(c);
      out.rhs(3 * i + 2) = g2 * mass_vs.row(i).dot(normal.transpose());
    }
  }

  void interface_mass(const InterfaceEdge& s, const Eigen::MatrixX2d& X,
                      std::vector<Eigen::Triplet<double>>& t) const override {
    const int na = mesh_.triangles(s.element, s.local[0]), nb = mesh_.triangles(s.element, s.local[1]);
    const double length = (X.row(nb) - X.row(na)).norm();
    t.emplace_back(s.iface[0], s.iface[0], length / 3.0);
    t.emplace_back(s.iface[1], s.iface[1], length / 3.0);
    t.emplace_back(s.iface[0], s.iface[1], length / 6.0);
    t.emplace_back(s.iface[1], s.iface[0], length / 6.0);
  }

  Eigen::VectorXd nodal_pressure(const Eigen::VectorXd& U) const override {
    Eigen::VectorXd p(mesh_.node_count());
    for (int i = 0; i < mesh_.node_count(); ++i) p(i) = U(3 * i + 2);
    return p;
  }
  Eigen::Vector2d velocity_at(int e, const Eigen::Vector3d& l, const Eigen::VectorXd& U) const override {
    Eigen::Vector2d v = Eigen::Vector2d::Zero();
    for (int k = 0; k < 3; ++k) v += l(k) * U.segment<2>(3 * mesh_.triangles(e, k));
    return v;
  }

 private:
  FluidMesh mesh_;
  bool reconstruct_ = false;
  Eigen::MatrixX2d element_viscous_;
};

}  // namespace

std::unique_ptr<FlowElement> make_p1p1_element(FluidMesh mesh) {
  return std::make_unique<P1P1Element>(std::move(mesh));
}

}  // namespace fsi::fluid::detail
