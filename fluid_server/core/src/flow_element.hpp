#pragma once
// The element parts of the fluid solver (flow_solver.cpp), private to fsi_fluid. FlowSolver
// owns the one path every element shares: time stepping (BDF, ALE mesh velocity), the
// Picard/Newton loop, the global assembly (pattern, threads, scatter), the Nitsche interface
// bookkeeping, the strong constraints, the linear solves, the reactions and the checkpoints.
// A FlowElement supplies what differs between elements:
//   - its mesh (checked, or converted) and the DOF layout,
//   - the local system of one triangle (element kernels: p1_element.hpp, p2p1_element.hpp),
//   - the traces on an interface edge: the Nitsche terms and the interface mass,
//   - the output: the pressure at every node, the velocity at a point of a triangle.
// The two parts, make_p1p1_element (flow_element_p1p1.cpp: P1/P1 SUPG/PSPG/LSIC) and
// make_p2p1_element (flow_element_p2p1.cpp: isoparametric Taylor-Hood P2/P1), are selected by
// the scene's fluid.element name; in 3D (FlowSolver3) make_p2p1_tet_element (10-node tetrahedra). (The midpoints of a
// 6-node mesh follow their vertices, in the P2 nodal pressure and in the vertex-driven mesh motion, by
// FluidMesh::interpolate_midpoints.)
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fsi/fluid/flow_solver.hpp"

namespace fsi::fluid::detail {

// Where the unknowns live: velocity component c of node i at velocity_stride i + c, the
// pressure of vertex v at pressure_offset + pressure_stride v.
struct DofLayout {
  int dofs = 0;
  int velocity_stride = 0;
  int pressure_offset = 0, pressure_stride = 0;
  int velocity(int node, int c) const { return velocity_stride * node + c; }
  int pressure(int vertex) const { return pressure_offset + pressure_stride * vertex; }
};

// What the local assembly of one nonlinear iteration reads (per node, or per unknown).
template <int Dim>
struct AssemblyInputT {
  const NodeMatrix<Dim>& X;              // positions (current configuration)
  const NodeMatrix<Dim>& mesh_velocity;  // w
  const NodeMatrix<Dim>& body;           // body force f
  const Eigen::VectorXd& U_lin;          // linearisation velocity u* (every unknown)
  const Eigen::VectorXd& history;        // (alpha1 u_n + alpha2 u_{n-1}) / dt (every unknown; 0 if steady)
  const FlowParameters& params;
  double alpha0_dt = 0, dt = 0;  // 0 if steady
};
using AssemblyInput = AssemblyInputT<2>;

// The local matrix and right-hand side of a triangle or an interface edge, in the element's
// local order of unknowns (element_dofs).
struct LocalSystem {
  Eigen::MatrixXd matrix;
  Eigen::VectorXd rhs;
};

// A boundary segment (2D) or face (3D) on the Nitsche interface: its element and the
// segment's or face's nodes, as local node numbers of the element and as interface indices.
// 2D: the triangle's edge k (vertices k, k + 1 mod 3); P1: the segment's two vertices in the
// group's order; P2: vertex k, vertex k + 1, midpoint 3 + k. 3D (10-node tetrahedra): `edge`
// is the local vertex opposite the face; the face's vertices a, b, c in the group's order,
// then the midpoints of ab, bc, ca.
struct InterfaceEdge {
  int element = 0, edge = 0;
  std::array<int, 6> local{}, iface{};
};

// What the Nitsche terms read.
template <int Dim>
struct NitscheInputT {
  const NodeMatrix<Dim>& X;    // current positions
  const NodeMatrix<Dim>& X_n;  // positions of the last accepted step (penalty_on_step_start)
  const Eigen::VectorXd& v_s;  // interface velocity, Dim per interface node
  const FlowParameters& params;
};
using NitscheInput = NitscheInputT<2>;

template <int Dim>
class FlowElementT {
 public:
  using AssemblyInput = AssemblyInputT<Dim>;
  using NitscheInput = NitscheInputT<Dim>;
  using Mesh = MeshOf<Dim>;
  virtual ~FlowElementT() = default;
  virtual const char* name() const = 0;  // fluid.element: "p1p1", "p2p1" (checkpoints)
  virtual const Mesh& mesh() const = 0;
  virtual DofLayout layout() const = 0;
  virtual int local_size() const = 0;                     // unknowns per triangle
  virtual void element_dofs(int e, int* dofs) const = 0;  // local_size() global unknowns
  // Halve a Newton update that grows the change (iterations 3 on)? P2/P1 yes; P1/P1 no (its
  // Newton, the Galerkin Jacobian with Picard stabilisation terms, has always run undamped).
  virtual bool damped_newton() const = 0;

  // --- local assembly ---
  virtual void prepare(const AssemblyInput&) {}  // once per iteration, before the triangles
  // Triangle e's local system (the matrix and rhs overwritten); false (with `bad`, the area or
  // the smallest det J) when the triangle is inverted or degenerate.
  virtual bool assemble(int e, const AssemblyInput& in, LocalSystem& out, double& bad) const = 0;
  // For the error on an inverted triangle: "element" / "6-node element", and what is wrong
  // with it ("inverted or degenerate (area -0.001)").
  virtual const char* cell_name() const = 0;
  virtual std::string inverted(double bad) const = 0;

  // --- interface traces ---
  // The interface edge on edge k of triangle e for the group's segment (a, b); `iface` maps
  // a mesh node to its interface index. Appends the edge's interface segments.
  virtual InterfaceEdge interface_edge(int e, int k, int a, int b, const std::map<int, int>& iface,
                                       std::vector<std::array<int, 2>>& segments) const = 0;
  // 3D: the interface face (a, b, c) = abc of tetrahedron e, the vertex opposite it
  // `opposite`; appends the face's interface nodes (gmsh order: a, b, c, ab, bc, ca).
  virtual InterfaceEdge interface_face(int, int, const std::array<int, 3>&, const std::map<int, int>&,
                                       std::vector<std::array<int, 6>>&) const {
    throw std::invalid_argument(std::string("the element ") + name() + " has no interface faces");
  }
  // -p int N_i n over the edge or face (outward normal n at positions X): the load of a
  // prescribed normal traction, in the element's local order (overwrites `load`).
  virtual void pressure_load(const InterfaceEdge&, const NodeMatrix<Dim>&, double, Eigen::VectorXd&) const {
    throw std::invalid_argument(std::string("the element ") + name() + " has no pressure boundaries");
  }
  // The backflow stabilisation on a traction boundary's face (overwrites `out.matrix`, `out.rhs`
  // zero): -coefficient int min((u* - w).n, 0) N_i N_j on each velocity component, u* the
  // linearisation velocity U_lin, w the mesh velocity, n outward (coefficient = beta rho).
  virtual void backflow(const InterfaceEdge&, const NodeMatrix<Dim>&, const Eigen::VectorXd&, const NodeMatrix<Dim>&,
                        double, LocalSystem&) const {
    throw std::invalid_argument(std::string("the element ") + name() + " has no backflow stabilisation");
  }
  // The Nitsche terms of the edge (overwrites `out`), in the triangle's local order.
  virtual void nitsche(const InterfaceEdge& edge, const NitscheInput& in, LocalSystem& out) const = 0;
  // int N_i N_j over the edge at positions X, on the interface indices.
  virtual void interface_mass(const InterfaceEdge& edge, const NodeMatrix<Dim>& X,
                              std::vector<Eigen::Triplet<double>>& mass) const = 0;

  // --- output ---
  virtual Eigen::VectorXd nodal_pressure(const Eigen::VectorXd& U) const = 0;
  virtual Point<Dim> velocity_at(int e, const Eigen::Matrix<double, Dim + 1, 1>& bary,
                                 const Eigen::VectorXd& U) const = 0;
};
using FlowElement = FlowElementT<2>;

// Each checks (P2/P1: converts a linear mesh to straight 6-node triangles) the mesh; throws
// std::invalid_argument when the element cannot use it.
std::unique_ptr<FlowElement> make_p1p1_element(FluidMesh mesh);
std::unique_ptr<FlowElement> make_p2p1_element(FluidMesh mesh);
// 3D: isoparametric Taylor-Hood P2/P1 on 10-node tetrahedra (flow_element_p2p1_tet.cpp; a
// linear mesh gets straight midpoints).
std::unique_ptr<FlowElementT<3>> make_p2p1_tet_element(TetMesh mesh);

}  // namespace fsi::fluid::detail
