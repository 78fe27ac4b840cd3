#pragma once
// An elastic support (foundation) on parts of the solid's boundary: the surrounding tissue of a
// vessel wall (Moireau et al. 2012, "External tissue support and fluid-structure simulation in
// blood flows"), a Winkler foundation, or the hoop stiffness a plane-strain model of a tube's
// wall lacks. Each boundary node carries the traction
//     t = -k_s (u . n) n      (direction normal)   or   t = -k_s u      (direction all)
// lumped with the node's share A of its facets (reference measure), n the node's outward
// reference normal (the area-weighted mean of its facets' normals). The force is linear in
// the displacement: residual += K_s u, tangent += K_s, with K_s = k_s A n n^T (or k_s A I) per
// node. A kernel: Eigen in, Eigen out; no I/O.
#include <Eigen/Core>
#include <vector>

#include "fsi/solid/mesh.hpp"

namespace fsi::solid {

struct SupportSpec {
  std::vector<Facet> facets;  // the supported boundary facets (each once)
  double stiffness = 0;       // k_s > 0: traction per displacement (Pa/m)
  bool normal_only = true;    // true: along the outward normal; false: every component
};

class ElasticSupport {
 public:
  // Throws std::invalid_argument for a non-positive stiffness or a facet of no cell.
  ElasticSupport(const SolidMesh& mesh, const std::vector<SupportSpec>& supports);

  // Adds K_s d to the full residual r (R = F_int - F_ext + K_s d + ...).
  void add_to_residual(const Eigen::VectorXd& d, Eigen::VectorXd& r) const;
  // Calls add(dof_i, dof_j, value) for every entry of K_s (a node's own dim x dim block).
  template <class Add>
  void add_to_tangent(Add&& add) const {
    for (const Node& n : nodes_)
      for (int i = 0; i < dim_; ++i)
        for (int j = 0; j < dim_; ++j) add(dim_ * n.node + i, dim_ * n.node + j, n.k(i, j));
  }
  int nodes() const { return static_cast<int>(nodes_.size()); }
  // The total support force on the solid, -K_s d (dim components).
  Eigen::VectorXd force(const Eigen::VectorXd& d) const;

 private:
  struct Node {
    int node;
    Eigen::MatrixXd k;  // dim x dim: sum over the supports of k_s A n n^T (or k_s A I)
  };
  int dim_ = 2;
  std::vector<Node> nodes_;
};

}  // namespace fsi::solid
