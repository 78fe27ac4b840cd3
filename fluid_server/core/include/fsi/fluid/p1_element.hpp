#pragma once
// Element kernels of the P1/P1 stabilised Navier-Stokes discretisation (pure functions,
// Eigen in/out, no I/O). Local unknowns are ordered per node: (u, v, p) of node 0, 1, 2.
//
// Momentum, linearised about the advection velocity a = u* - w (ALE: w = mesh velocity):
//   rho (alpha0 u + history)/dt + rho (a . grad) u - div(mu grad u) + grad p = f,  div u = 0
// Weak form (pseudo-stress sigma = mu grad u - p I, as in the seed paper):
//   (w, rho(alpha0/dt u + a.grad u)) + (mu grad w, grad u) - (div w, p) + (q, div u)
//   + sum_K (tau_M (a.grad w + grad q / rho), r_M)_K + sum_K (tau_C rho div w, div u)_K
//   = (w, f - rho history/dt) + stabilisation right-hand side,
// with the strong residual r_M = rho(alpha0/dt u + history/dt + a.grad u) + grad p - div(mu grad u) - f.
// The viscous term vanishes inside linear elements; with `viscous_residual` the caller passes
// div(mu grad u*) reconstructed from the L2-projected nodal gradient of the linearisation
// velocity u* (Jansen, Collis, Whiting & Shakib, CMAME 174 (1999) 153), which restores the
// consistency of SUPG/PSPG in boundary layers (explicit in u*, so the matrix is unchanged).
#include <Eigen/Core>

#include "fsi/fluid/flow_solver.hpp"  // StabilisationParameters

namespace fsi::fluid {

struct ElementInput {
  Eigen::Matrix<double, 3, 2> x;          // node positions (current configuration)
  Eigen::Matrix<double, 3, 2> advection;  // a = u* - w at the nodes
  Eigen::Matrix<double, 3, 2> history;    // (alpha1 u_n + alpha2 u_{n-1}) / dt at the nodes (0 if steady)
  Eigen::Matrix<double, 3, 2> force;      // body force f at the nodes
  Eigen::Matrix<double, 3, 2> velocity = Eigen::Matrix<double, 3, 2>::Zero();  // u_k (Newton linearisation point)
  bool newton = false;  // add the Galerkin convection Jacobian (du . grad) u_k (SUPG/PSPG/tau stay Picard)
  Eigen::RowVector2d viscous = Eigen::RowVector2d::Zero();  // div(mu grad u*) in the element (0: not reconstructed)
  double density = 1;
  double viscosity = 1;  // dynamic
  double alpha0_dt = 0;  // alpha0 / dt (0 if steady)
  double dt = 0;         // for tau (0 = steady)
};

struct ElementOutput {
  Eigen::Matrix<double, 9, 9> matrix;
  Eigen::Matrix<double, 9, 1> rhs;
  double tau_m = 0, tau_c = 0;
};

struct TriangleGeometry {
  double area = 0;
  Eigen::Matrix<double, 3, 2> grad;  // grad N_k (rows)
};

// Throws nothing; area <= 0 means an inverted or degenerate element (caller reports it).
TriangleGeometry triangle_geometry(const Eigen::Matrix<double, 3, 2>& x);

void assemble_element(const ElementInput& in, const StabilisationParameters& stab, ElementOutput& out);

}  // namespace fsi::fluid
