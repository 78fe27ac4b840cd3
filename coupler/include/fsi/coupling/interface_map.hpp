#pragma once
// Mapping between the solid's and the fluid's interface nodes (they need not match).
//  - displacement and velocity: consistent interpolation, x_f = H x_s, each fluid node
//    takes the linear interpolant of the solid's interface polyline at its closest point;
//  - forces: the transpose, F_s = H^T f_f (conservative), so that the power across the
//    interface is the same on both sides: F_s . v_s = f_f . v_f exactly.
// A point interface (no segments) maps node to nearest node. In 3D the same with faces: each
// fluid node takes the solid's face interpolant at its closest point on the solid's faces
// (triangles and quadrilaterals, linear or quadratic), forces again by H^T.
// Radial basis functions instead (MappingSettings): H interpolates the solid's nodal values
// at the fluid's nodes by s(x) = sum_j lambda_j phi(|x - x_j|) + a + b . x over the solid's
// interface nodes (segments unused), forces again by H^T. The linear term makes H exact for
// every affine field u(x) = A x + c (rigid translations and rotations of any angle among
// them), at fluid nodes on or off the solid's boundary; H 1 = 1, so H^T keeps the sum of the
// forces, and H^T keeps the interface work f_f . H v_s = (H^T f_f) . v_s, both to round-off.
// Conforming interface: as many fluid as solid nodes, and every fluid node within
// 1e-9 of the interface's size (the diagonal of the box around both node sets) of a
// different solid node; H is then a permutation P (to round-off: its rows are the
// projections on the solid polyline, within gap / segment length of P's unit rows).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <string>

#include "fsi/common/interface_geometry.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi::coupling {

// coupling.mapping: the nearest-segment projection (above), or RBF interpolation with a
// thin-plate spline phi(r) = r^2 log r, or Wendland's C2 function
// phi(r) = (1 - r/R)^4 (1 + 4 r/R) for r < R (preCICE's compact-polynomial-c2).
enum class MappingKind { NearestSegment, RbfThinPlateSpline, RbfWendlandC2 };

struct MappingSettings {
  MappingKind kind = MappingKind::NearestSegment;
  // Wendland C2's support radius R; 0 = support_factor x the solid's node spacing (the
  // largest distance from an interface node to its nearest neighbour).
  double support_radius = 0;
  static constexpr double support_factor = 50.0;
};

std::string to_string(MappingKind k);

class InterfaceMap {
 public:
  InterfaceMap() = default;
  // `solid` and `fluid` in the reference configuration.
  InterfaceMap(const InterfaceMeshData& solid, const InterfaceMeshData& fluid, const MappingSettings& mapping = {});
  Eigen::VectorXd to_fluid(const Eigen::VectorXd& solid_values) const { return h_ * solid_values; }
  Eigen::VectorXd to_solid(const Eigen::VectorXd& fluid_forces) const { return ht_ * fluid_forces; }
  const Eigen::SparseMatrix<double>& matrix() const { return h_; }
  // M_G = H^T M_f H for a scalar matrix on the fluid's interface nodes (e.g. its interface
  // mass): the same operator seen from the solid's nodes, so that v_s . M_G v_s = v_f . M_f v_f
  // for v_f = H v_s.
  NodalMatrix mass_to_solid(const NodalMatrix& fluid_mass) const;
  double max_gap() const { return max_gap_; }  // largest fluid-node-to-solid distance
  bool conforming() const { return conforming_; }
  // Fluid nodes that coincide (within coincidence_tolerance) with a solid node.
  Eigen::Index coincident_nodes() const { return coincident_nodes_; }
  double coincidence_tolerance() const { return tolerance_; }
  // max |H - P| over the entries of the scalar H, P the permutation; 0 unless conforming.
  double permutation_error() const { return permutation_error_; }
  MappingKind kind() const { return kind_; }
  // RBF: the support radius used (Wendland C2; 0 for the thin-plate spline), the linear
  // terms kept (2 in the plane; 1 for nodes on a line, 0 for a single node) and the
  // condition number estimate of the interpolation system on the null space of the linear
  // terms (reciprocal of its Cholesky factorisation's rcond).
  double support_radius() const { return support_radius_; }
  int linear_terms() const { return linear_terms_; }
  double condition_estimate() const { return condition_; }

 private:
  // Whether H is a permutation (conforming meshes): coincident_nodes_, conforming_, permutation_error_.
  template <int D>
  void detect_conforming(const InterfaceMeshData& solid, const InterfaceMeshData& fluid);
  // Replaces hs_ by the RBF interpolation matrix (n_f x n_s, dense).
  template <int D>
  void build_rbf(const InterfaceMeshData& solid, const InterfaceMeshData& fluid, const MappingSettings& mapping);
  // 3D: the closest-point projection onto the solid's faces.
  void build_nearest_3d(const InterfaceMeshData& solid, const InterfaceMeshData& fluid);
  void set_from_scalar(const Eigen::MatrixXd& hs);
  Eigen::SparseMatrix<double> h_, ht_;
  Eigen::SparseMatrix<double> hs_, hst_;  // the scalar (per node) H, n_f x n_s, and its transpose
  Eigen::MatrixXd hs_dense_;              // RBF: the same, dense (empty for the projection)
  double max_gap_ = 0;
  bool conforming_ = false;
  Eigen::Index coincident_nodes_ = 0;
  double tolerance_ = 0;
  double permutation_error_ = 0;
  MappingKind kind_ = MappingKind::NearestSegment;
  double support_radius_ = 0;
  int linear_terms_ = 0;
  double condition_ = 0;
  int dim_ = 2;  // values per node
};

// 3D interfaces of faces on both sides (InterfaceMap's constructor calls it): each side's
// faces form a surface (every edge between corner nodes has one or two faces, and two faces
// run along their common edge in opposite directions), and the two surfaces end on the same
// boundary: every boundary edge (an edge of one face) of either side lies within half the
// element size of a boundary edge of the other (plus its distance to the other's surface:
// an offset interface is coupling.interface_gap's to judge). Closed surfaces have no boundary edges; an
// open one (a flag's surface, ending on a wall) must end where the other side's ends. Throws
// std::invalid_argument naming the side, the edge and the distance otherwise. Point
// interfaces (no faces) are not checked.
void check_interface_surfaces(const InterfaceMeshData& solid, const InterfaceMeshData& fluid);

// M_G = int N^T N dgamma on the solid interface (dn x dn, consistent, current
// configuration = reference + displacement); diag(lumped_measure) for a point interface.
Eigen::SparseMatrix<double> interface_mass(const InterfaceMeshData& solid, const Eigen::VectorXd& displacement);
// The same as a scalar matrix on the solid's interface nodes (n x n): fsi::nodal_interface_mass.
using fsi::nodal_interface_mass;

}  // namespace fsi::coupling
