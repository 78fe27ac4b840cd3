#pragma once
// Mapping between the solid's and the fluid's interface nodes (they need not match).
//  - displacement and velocity: consistent interpolation, x_f = H x_s, each fluid node
//    takes the linear interpolant of the solid's interface polyline at its closest point;
//  - forces: the transpose, F_s = H^T f_f (conservative), so that the power across the
//    interface is the same on both sides: F_s . v_s = f_f . v_f exactly.
// A point interface (no segments) maps node to nearest node.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "fsi/common/solver_model.hpp"

namespace fsi::coupling {

class InterfaceMap {
 public:
  InterfaceMap() = default;
  // `solid` and `fluid` in the reference configuration.
  InterfaceMap(const InterfaceMeshData& solid, const InterfaceMeshData& fluid);
  Eigen::VectorXd to_fluid(const Eigen::VectorXd& solid_values) const { return h_ * solid_values; }
  Eigen::VectorXd to_solid(const Eigen::VectorXd& fluid_forces) const { return ht_ * fluid_forces; }
  const Eigen::SparseMatrix<double>& matrix() const { return h_; }
  double max_gap() const { return max_gap_; }  // largest fluid-node-to-solid distance

 private:
  Eigen::SparseMatrix<double> h_, ht_;
  double max_gap_ = 0;
};

// M_G = int N^T N dgamma on the solid interface (2n x 2n, consistent, current
// configuration = reference + displacement); diag(lumped_measure) for a point interface.
Eigen::SparseMatrix<double> interface_mass(const InterfaceMeshData& solid, const Eigen::VectorXd& displacement);

}  // namespace fsi::coupling
