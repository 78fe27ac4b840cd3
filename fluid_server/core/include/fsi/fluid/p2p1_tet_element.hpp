#pragma once
// Element kernels of the isoparametric Taylor-Hood P2/P1 discretisation on tetrahedra (pure
// functions, Eigen in/out, no I/O): the 3D counterpart of p2p1_element.hpp, the same weak form.
// 10-node tetrahedra: vertices 0-3 (positive volume), then the midpoints of the edges
// 01, 12, 20, 30, 32, 31 (gmsh's order, kTetEdges; possibly curved: the element map is quadratic).
// Local unknowns: (u, v, w) of node 0..9 at 3k, 3k+1, 3k+2, then p of vertex 0..3 at 30 + k.
//
// Momentum, linearised about the advection velocity a = u* - w_mesh:
//   (v, rho (alpha0/dt u + a.grad u)) + (mu grad v, grad u) - (div v, p) + (q, div u)
//   [+ Newton: (v, rho (u . grad) u_k) on the left and (v, rho (u_k . grad) u_k) on the right]
//   [+ grad-div: gamma (div v, div u)]
//   = (v, f - rho history)
// No SUPG (Taylor-Hood is inf-sup stable; the 3D cases here are at moderate Reynolds numbers).
#include <Eigen/Core>
#include <array>

namespace fsi::fluid {

struct P2TetInput {
  Eigen::Matrix<double, 10, 3> x;          // node positions (current configuration)
  Eigen::Matrix<double, 10, 3> advection;  // a = u* - w at the nodes
  Eigen::Matrix<double, 10, 3> velocity;   // u_k (Newton linearisation point)
  Eigen::Matrix<double, 10, 3> history;    // (alpha1 u_n + alpha2 u_{n-1}) / dt (0 if steady)
  Eigen::Matrix<double, 10, 3> force;      // body force f at the nodes
  double density = 1;
  double viscosity = 1;  // dynamic
  double alpha0_dt = 0;  // alpha0 / dt (0 if steady)
  double grad_div = 0;   // gamma
  bool newton = false;
};

struct P2TetOutput {
  Eigen::Matrix<double, 34, 34> matrix;
  Eigen::Matrix<double, 34, 1> rhs;
  double min_jacobian = 0;  // smallest det J at the quadrature points (<= 0: inverted or badly curved)
};

struct TetQuadraturePoint {
  double x, y, z, weight;  // reference coordinates; the weights sum to 1/6
};
// 14-point rule, exact for polynomials of degree 5 on the reference tetrahedron.
const std::array<TetQuadraturePoint, 14>& tet_quadrature();

// Quadratic shape functions at the reference point and their reference gradients.
void p2_tet_shape(double x, double y, double z, Eigen::Matrix<double, 10, 1>& N, Eigen::Matrix<double, 10, 3>& dN);

// Returns false (out.min_jacobian <= 0) when det J <= 0 at a quadrature point.
bool assemble_p2p1_tet(const P2TetInput& in, P2TetOutput& out);

// Smallest det J of the element map at the quadrature points and the vertices.
double p2_tet_min_jacobian(const Eigen::Matrix<double, 10, 3>& x);

}  // namespace fsi::fluid
