#pragma once
// Element kernels of the isoparametric Taylor-Hood P2/P1 discretisation (pure functions,
// Eigen in/out, no I/O). 6-node triangles: vertices 0-2 (counter-clockwise), then the
// midpoints of edges 01, 12, 20 (possibly curved: the element map is quadratic).
// Local unknowns: (u, v) of node 0..5 at 2k, 2k+1, then p of vertex 0..2 at 12 + k.
//
// Momentum, linearised about the advection velocity a = u* - w (ALE: w = mesh velocity):
//   (w, rho (alpha0/dt u + a.grad u)) + (mu grad w, grad u) - (div w, p) + (q, div u)
//   [+ Newton: (w, rho (u . grad) u_k) on the left and (w, rho (u_k . grad) u_k) on the right]
//   [+ grad-div: gamma (div w, div u)]
//   [+ SUPG: sum_K (tau_M rho a.grad w, r_M)_K, r_M = rho(alpha0/dt u + history + a.grad u)
//      + grad p - mu lap u - f, the Laplacian from the vertices' affine map]
//   = (w, f - rho history)
// The pseudo-stress sigma = mu grad u - p I is the seed paper's (do-nothing outlets).
#include <Eigen/Core>

#include "fsi/fluid/flow_solver.hpp"

namespace fsi::fluid {

struct P2ElementInput {
  Eigen::Matrix<double, 6, 2> x;          // node positions (current configuration)
  Eigen::Matrix<double, 6, 2> advection;  // a = u* - w at the nodes
  Eigen::Matrix<double, 6, 2> velocity;   // u_k (Newton linearisation point; unused otherwise)
  Eigen::Matrix<double, 6, 2> history;    // (alpha1 u_n + alpha2 u_{n-1}) / dt at the nodes (0 if steady)
  Eigen::Matrix<double, 6, 2> force;      // body force f at the nodes
  double density = 1;
  double viscosity = 1;  // dynamic
  double alpha0_dt = 0;  // alpha0 / dt (0 if steady)
  double dt = 0;         // for tau (0 = steady)
  bool newton = false;
};

struct P2ElementOutput {
  Eigen::Matrix<double, 15, 15> matrix;
  Eigen::Matrix<double, 15, 1> rhs;
  double min_jacobian = 0;  // smallest det J at the quadrature points (<= 0: inverted or badly curved)
};

// Quadratic shape functions at the reference point (xi, eta) and their reference gradients.
void p2_shape(double xi, double eta, Eigen::Matrix<double, 6, 1>& N, Eigen::Matrix<double, 6, 2>& dN);

// Returns false (and leaves `out.min_jacobian` <= 0) when det J <= 0 at a quadrature point.
bool assemble_p2p1_element(const P2ElementInput& in, const StabilisationParameters& stab, P2ElementOutput& out);

// Smallest det J of the element map at the quadrature points and the vertices.
double p2_min_jacobian(const Eigen::Matrix<double, 6, 2>& x);

}  // namespace fsi::fluid
