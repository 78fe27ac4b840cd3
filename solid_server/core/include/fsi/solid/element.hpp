#pragma once
// Total Lagrangian isoparametric elements, one code for both dimensions (templated on the
// shape): the bilinear quadrilateral Quad4 (plane strain, unit thickness, 2x2 Gauss; node
// order counter-clockwise), the trilinear hexahedron Hex8 (2x2x2 Gauss; VTK node order:
// the bottom face zeta = -1 counter-clockwise seen from above, then the top face alike) and
// the quadratic tetrahedron Tet10 (14-point rule of degree 5; gmsh node order).
// Dofs interleaved [x0, y0, (z0,) x1, ...]. Kernels take and return Eigen types; no I/O.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <vector>

#include "fsi/solid/material.hpp"

namespace fsi::solid {

// The element's formulation: plain displacement, or with enhanced assumed strains (EAS;
// the same nodes and dofs). Q4 / Q4Eas on 2D meshes, Hex8 / Hex8Eas on 3D meshes.
enum class ElementKind { Q4, Q4Eas, Hex8, Hex8Eas, Tet10 };
inline bool is_enhanced(ElementKind k) { return k == ElementKind::Q4Eas || k == ElementKind::Hex8Eas; }

// The reference shapes: node count, shape functions on the reference cell ([-1, 1]^dim, or
// the unit tetrahedron), the Gauss rule of the kernels, the EAS modes (natural strains, Voigt
// order of material.hpp with doubled shears; none for Tet10), the reference centre and
// extent(xi): <= 1 inside the reference cell, > 1 outside (the probes' cell search).
struct Quad4 {
  static constexpr int dim = 2, nodes = 4, gauss_points = 4, eas_modes = 4;
  using Point = Eigen::Vector2d;
  static Eigen::Matrix<double, 4, 1> shape(const Point& xi);
  static Eigen::Matrix<double, 4, 2> derivatives(const Point& xi);  // dN/dxi
  static const std::array<std::pair<Point, double>, 4>& gauss();    // 2x2, xi outer
  // Andelfinger & Ramm (1993) Q1E4: E_xixi ~ xi, E_etaeta ~ eta, 2 E_xieta ~ [xi, eta].
  static Eigen::Matrix<double, 3, 4> enhanced_modes(const Point& xi);
  static Point centre() { return Point::Zero(); }
  static double extent(const Point& xi) { return xi.cwiseAbs().maxCoeff(); }
};
struct Hex8 {
  static constexpr int dim = 3, nodes = 8, gauss_points = 8, eas_modes = 9;
  using Point = Eigen::Vector3d;
  static Eigen::Matrix<double, 8, 1> shape(const Point& xi);
  static Eigen::Matrix<double, 8, 3> derivatives(const Point& xi);
  static const std::array<std::pair<Point, double>, 8>& gauss();  // 2x2x2, xi outer
  // Andelfinger & Ramm (1993) H1E9: each normal natural strain linear in its own coordinate,
  // each doubled shear 2 E_AB ~ [xi_A, xi_B] (9 modes).
  static Eigen::Matrix<double, 6, 9> enhanced_modes(const Point& xi);
  static Point centre() { return Point::Zero(); }
  static double extent(const Point& xi) { return xi.cwiseAbs().maxCoeff(); }
};
// Quadratic tetrahedron on {xi, eta, zeta >= 0, xi + eta + zeta <= 1}, gmsh's node order:
// the vertices (0,0,0), (1,0,0), (0,1,0), (0,0,1), then the midpoints of the edges 0-1, 1-2,
// 2-0, 0-3, 2-3, 1-3 (VTK's quadratic tetrahedron has the last two swapped). Plain
// displacement (no EAS modes); quadratic fields do not lock in bending. The 14-point rule
// (Walkington) is exact for degree 5: the mass matrix (degree 4) exactly, the internal
// force's integrand cof(J) grad N (degree 3) exactly on curved cells, so the patch test holds.
struct Tet10 {
  static constexpr int dim = 3, nodes = 10, gauss_points = 14, eas_modes = 0;
  using Point = Eigen::Vector3d;
  static Eigen::Matrix<double, 10, 1> shape(const Point& xi);
  static Eigen::Matrix<double, 10, 3> derivatives(const Point& xi);
  static const std::array<std::pair<Point, double>, 14>& gauss();  // weights sum to 1/6
  static Eigen::Matrix<double, 6, 0> enhanced_modes(const Point&) { return {}; }
  static Point centre() { return Point::Constant(0.25); }
  // 1 - 2 min(barycentric coordinates): 0.5 at the centre, 1 on the faces.
  static double extent(const Point& xi) {
    return 1 - 2 * std::min(std::min(1 - xi.sum(), xi(0)), std::min(xi(1), xi(2)));
  }
  // The local nodes (vertices, then the edge midpoints in gmsh's triangle order) of face f,
  // right-handed outward: faces (0,2,1), (0,1,3), (1,2,3), (0,3,2).
  static const std::array<std::array<int, 6>, 4>& faces();
};

template <class Shape>
struct ElementTraits {
  static constexpr int dim = Shape::dim, nodes = Shape::nodes, dofs = Shape::nodes * Shape::dim;
  using Coords = Eigen::Matrix<double, nodes, dim>;  // reference coordinates X, row per node
  using Vector = Eigen::Matrix<double, dofs, 1>;
  using Matrix = Eigen::Matrix<double, dofs, dofs>;
  using Tensor = Eigen::Matrix<double, dim, dim>;
};

template <class Shape>
struct ElementStateT {
  typename ElementTraits<Shape>::Vector internal_force = ElementTraits<Shape>::Vector::Zero();  // int B^T S dV
  typename ElementTraits<Shape>::Matrix tangent = ElementTraits<Shape>::Matrix::Zero();         // material + geometric
  double min_det_F = 1;                                                                         // over the Gauss points
  double min_det_jacobian = 1;                                                                  // of the reference map
};

// Internal force and consistent tangent for displacement u. When `with_tangent` is false
// only the force is computed.
template <class Shape>
ElementStateT<Shape> internal_force(const typename ElementTraits<Shape>::Coords& X,
                                    const typename ElementTraits<Shape>::Vector& u,
                                    const MaterialLaw<Shape::dim>& material, bool with_tangent = true);

// The same with enhanced assumed strains: E = E(u) + G(xi) alpha with the shape's modes on
// the Green-Lagrange strain, transformed with the Jacobian at the centre (Simo & Rifai
// 1990), and alpha condensed out per element (a local Newton from alpha = 0 every call, so
// the element has no state). Removes shear (and, with the normal modes, volumetric)
// locking in bending.
template <class Shape>
ElementStateT<Shape> eas_internal_force(const typename ElementTraits<Shape>::Coords& X,
                                        const typename ElementTraits<Shape>::Vector& u,
                                        const MaterialLaw<Shape::dim>& material, bool with_tangent = true);

// Consistent mass rho int N^T N dV.
template <class Shape>
typename ElementTraits<Shape>::Matrix element_mass(const typename ElementTraits<Shape>::Coords& X, double density);

// Body force int N^T b dV for a constant force per reference volume b.
template <class Shape>
typename ElementTraits<Shape>::Vector element_body_force(const typename ElementTraits<Shape>::Coords& X,
                                                         const Eigen::Matrix<double, Shape::dim, 1>& b);

// Deformation gradient at xi.
template <class Shape>
typename ElementTraits<Shape>::Tensor deformation_gradient(const typename ElementTraits<Shape>::Coords& X,
                                                           const typename ElementTraits<Shape>::Vector& u,
                                                           const typename Shape::Point& xi);

// Natural coordinates of point p in the element (Newton on the isoparametric map from the
// centre); returns false when it did not converge. Inside when Shape::extent(xi) <= 1
// (+tolerance).
template <class Shape>
bool inverse_map(const typename ElementTraits<Shape>::Coords& X, const typename Shape::Point& p,
                 typename Shape::Point& xi);

// ---- The 2D names (Q4) used throughout the 2D code and its tests.
using ElementCoords = ElementTraits<Quad4>::Coords;
using ElementVector = ElementTraits<Quad4>::Vector;
using ElementMatrix = ElementTraits<Quad4>::Matrix;
using ElementState = ElementStateT<Quad4>;

inline Eigen::Vector4d q4_shape(double xi, double eta) { return Quad4::shape({xi, eta}); }
inline Eigen::Matrix<double, 4, 2> q4_shape_derivatives(double xi, double eta) { return Quad4::derivatives({xi, eta}); }
// Gauss rule with n = 1..3 points per direction: (xi, eta, weight).
std::vector<std::array<double, 3>> gauss_rule_2d(int n);
inline ElementState q4_internal_force(const ElementCoords& X, const ElementVector& u, const Material& material,
                                      bool with_tangent = true) {
  return internal_force<Quad4>(X, u, material, with_tangent);
}
inline ElementState q4_eas_internal_force(const ElementCoords& X, const ElementVector& u, const Material& material,
                                          bool with_tangent = true) {
  return eas_internal_force<Quad4>(X, u, material, with_tangent);
}
inline ElementMatrix q4_mass(const ElementCoords& X, double density) { return element_mass<Quad4>(X, density); }
inline ElementVector q4_body_force(const ElementCoords& X, const Eigen::Vector2d& b) {
  return element_body_force<Quad4>(X, b);
}
inline Matrix2 q4_deformation_gradient(const ElementCoords& X, const ElementVector& u, double xi, double eta) {
  return deformation_gradient<Quad4>(X, u, {xi, eta});
}
inline bool q4_inverse_map(const ElementCoords& X, const Eigen::Vector2d& p, Eigen::Vector2d& xi) {
  return inverse_map<Quad4>(X, p, xi);
}

// Consistent 1D mass of a straight 2-node edge, weight * int N^T N ds (4x4, dofs
// [x0, y0, x1, y1]); reference length.
Eigen::Matrix4d edge_mass(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double weight);

// int N_a ds over a bilinear quadrilateral face (4 nodes in order, 3D coordinates as rows):
// the share of each node of a constant traction (2x2 Gauss).
Eigen::Vector4d quad_face_weights(const Eigen::Matrix<double, 4, 3>& X);

// int N_a n dA over a bilinear quadrilateral face (row a; 2x2 Gauss), n the unit normal by
// the right-hand rule of the node order: the share of each node of a unit pressure's force.
Eigen::Matrix<double, 4, 3> quad_face_area_vectors(const Eigen::Matrix<double, 4, 3>& X);

// The same for a 3D face of 4 nodes (bilinear quadrilateral: the two functions above) or 6
// nodes (quadratic triangle, gmsh order; the 7-point rule of interface_geometry.hpp): rows of
// X are the nodes. int N_a dA of a flat 6-node triangle is 0 at the vertices and A/3 at the
// edge midpoints (the consistent share of a constant traction).
Eigen::VectorXd face_weights(const Eigen::MatrixXd& X);
Eigen::MatrixXd face_area_vectors(const Eigen::MatrixXd& X);
// A positive share of the face's area per node, summing to the area: int N_a dA for a
// bilinear quadrilateral; for a 6-node triangle, whose vertex shares int N_a dA vanish, the
// diagonal of int N^T N dA scaled to the area (HRZ lumping: 1/19 of the area per vertex,
// 16/57 per midpoint on a flat face). Penalty springs (contact, elastic supports) use it.
Eigen::VectorXd face_lumped_weights(const Eigen::MatrixXd& X);

}  // namespace fsi::solid
