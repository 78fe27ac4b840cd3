#pragma once
// Total Lagrangian bilinear quadrilateral (Q4), plane strain, unit thickness, 2x2 Gauss.
// Node order counter-clockwise; dofs interleaved [x0, y0, x1, y1, ...].
// Kernels take and return Eigen types; no I/O.
#include <Eigen/Core>
#include <array>

#include "fsi/solid/material.hpp"

namespace fsi::solid {

using ElementCoords = Eigen::Matrix<double, 4, 2>;  // reference coordinates X, row per node
using ElementVector = Eigen::Matrix<double, 8, 1>;
using ElementMatrix = Eigen::Matrix<double, 8, 8>;

// The quadrilateral's formulation: plain displacement Q4, or Q4 with enhanced assumed strains.
enum class ElementKind { Q4, Q4Eas };

// Shape functions and their derivatives on [-1, 1]^2 at (xi, eta).
Eigen::Vector4d q4_shape(double xi, double eta);
Eigen::Matrix<double, 4, 2> q4_shape_derivatives(double xi, double eta);  // dN/dxi, dN/deta

// Gauss rule with n = 1..3 points per direction: (xi, eta, weight).
std::vector<std::array<double, 3>> gauss_rule_2d(int n);

struct ElementState {
  ElementVector internal_force = ElementVector::Zero();  // int B^T S dV
  ElementMatrix tangent = ElementMatrix::Zero();         // material + geometric
  double min_det_F = 1;                                  // over the Gauss points
  double min_det_jacobian = 1;                           // of the reference map
};

// Internal force and consistent tangent for displacement u (8). When `with_tangent` is
// false only the force is computed.
ElementState q4_internal_force(const ElementCoords& X, const ElementVector& u, const Material& material,
                               bool with_tangent = true);

// The same with enhanced assumed strains (EAS, Q4E4): E = E(u) + G(xi) alpha with the four
// modes [xi, eta, xi, eta] of Andelfinger & Ramm (1993) on the Green-Lagrange strain,
// transformed with the Jacobian at the centre (Simo & Rifai 1990), and alpha condensed
// out per element (a local Newton from alpha = 0 every call, so the element has no state).
// Removes the Q4's shear locking in bending; the same nodes and dofs as the Q4.
ElementState q4_eas_internal_force(const ElementCoords& X, const ElementVector& u, const Material& material,
                                   bool with_tangent = true);

// Consistent mass rho int N^T N dV (8x8).
ElementMatrix q4_mass(const ElementCoords& X, double density);

// Body force int N^T b dV for a constant force per reference volume b.
ElementVector q4_body_force(const ElementCoords& X, const Eigen::Vector2d& b);

// Deformation gradient at (xi, eta).
Matrix2 q4_deformation_gradient(const ElementCoords& X, const ElementVector& u, double xi, double eta);

// Consistent 1D mass of a straight 2-node edge, weight * int N^T N ds (4x4, dofs
// [x0, y0, x1, y1]); reference length.
Eigen::Matrix4d edge_mass(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double weight);

// Natural coordinates of point p in the element (Newton on the bilinear map); returns
// false when it did not converge. Inside when both |xi|, |eta| <= 1 (+tolerance).
bool q4_inverse_map(const ElementCoords& X, const Eigen::Vector2d& p, Eigen::Vector2d& xi);

}  // namespace fsi::solid
