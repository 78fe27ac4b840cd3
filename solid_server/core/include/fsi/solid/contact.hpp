#pragma once
// Contact of the solid's boundary with rigid obstacles: half-planes in 2D, half-spaces in 3D,
// each given by a point on its surface and its outward normal (pointing into the space the
// solid may fill). A smooth penalty keeps a layer of thickness about g_c between the two, so
// a fluid that fills the gap keeps at least one cell there.
//
// Gap of a boundary node: g = n . (X + d - p). Below the contact gap g_c the node carries the
// contact pressure
//     p(g) = k_n (g_c - g)^2 / g_c     (g < g_c; 0 otherwise),
// lumped with the node's share A of its boundary facets (reference measure), as the force
// f = A p(g) n. p and dp/dg are continuous at g = g_c (Newton keeps its quadratic rate through
// contact onset) and p is positive definite in its tangent A (-dp/dg) n n^T. At equilibrium
// under a pressure P the gap is g = g_c - sqrt(P g_c / k_n): with k_n = E / h the layer gives
// way by a small fraction of g_c for any load well below E g_c / h.
//
// Nodes whose every component is held (clamps) and nodes that start within g_c of an
// obstacle (e.g. next to a clamp on the obstacle's surface) are not contact nodes of it.
//
// Usage (SolidSystem calls add_to_residual/add_to_tangent while it assembles):
//   ObstacleContact contact(mesh, obstacles, facets, fixed);   // candidates()/excluded() for logs
//   ContactState s = contact.measure(d);                       // after a step: gaps, forces
// A kernel: Eigen in, Eigen out; no I/O.
#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

#include "fsi/solid/mesh.hpp"

namespace fsi::solid {

struct Obstacle {
  Eigen::VectorXd point;   // on the obstacle's surface (dim components)
  Eigen::VectorXd normal;  // outward (unit after the constructor), into the solid's side
  double contact_gap = 0;  // g_c > 0: the pressure acts for g < g_c
  double stiffness = 0;    // k_n > 0 (pressure per length): p(g) = k_n (g_c - g)^2 / g_c
};

// The contact pressure and its derivative dp/dg at gap g (zero for g >= g_c).
double contact_pressure(const Obstacle& o, double g);
double contact_pressure_derivative(const Obstacle& o, double g);

// The state of the contact at a displacement: what the run reports.
struct ContactState {
  double min_gap = 1e300;         // smallest gap over every contact node (any obstacle)
  Eigen::VectorXd min_gap_point;  // where (current position of that node)
  int active_nodes = 0;           // nodes with g < g_c
  Eigen::VectorXd force;          // total contact force on the solid (dim components)
  Eigen::VectorXd lower, upper;   // bounding box of the active nodes (current positions; empty: none)
};

struct ObstacleError : std::invalid_argument {
  ObstacleError(int index, const std::string& what) : std::invalid_argument(what), obstacle(index) {}
  int obstacle;  // index into the obstacles
};

class ObstacleContact {
 public:
  // `facets[o]`: the boundary facets that may touch obstacle o; `fixed`: one flag per dof.
  // Throws ObstacleError when a free node of the facets starts inside its obstacle (g < 0) or
  // when an obstacle's normal is zero or of the wrong dimension.
  ObstacleContact(const SolidMesh& mesh, std::vector<Obstacle> obstacles, const std::vector<std::vector<Facet>>& facets,
                  const std::vector<char>& fixed);

  const std::vector<Obstacle>& obstacles() const { return obstacles_; }
  // Contact nodes of obstacle o, and the free boundary nodes left out because they start within g_c.
  int candidates(int o) const { return static_cast<int>(nodes_[static_cast<std::size_t>(o)].size()); }
  int excluded(int o) const { return excluded_[static_cast<std::size_t>(o)]; }

  // Adds -f_contact(d) to the full residual r (R = F_int - F_ext - f_contact + ...).
  void add_to_residual(const Eigen::VectorXd& d, Eigen::VectorXd& r) const;
  // Calls add(dof_i, dof_j, value) for every entry of dR/dd of the active nodes (a node's own
  // dim x dim block; fixed dofs included: the caller skips them).
  template <class Add>
  void add_to_tangent(const Eigen::VectorXd& d, Add&& add) const {
    for_each_active(d, [&](const Obstacle& o, int node, double area, double g) {
      const double k = -area * contact_pressure_derivative(o, g);
      for (int i = 0; i < dim_; ++i)
        for (int j = 0; j < dim_; ++j) add(dim_ * node + i, dim_ * node + j, k * o.normal(i) * o.normal(j));
    });
  }
  ContactState measure(const Eigen::VectorXd& d) const;
  double gap(const Obstacle& o, int node, const Eigen::VectorXd& d) const {
    return o.normal.dot(X_.row(node).transpose() + d.segment(dim_ * node, dim_) - o.point);
  }

 private:
  struct Node {
    int node;
    double area;  // lumped reference measure of the contact facets at the node
  };
  template <class F>
  void for_each_active(const Eigen::VectorXd& d, F&& f) const {
    for (std::size_t o = 0; o < obstacles_.size(); ++o)
      for (const Node& n : nodes_[o]) {
        const double g = gap(obstacles_[o], n.node, d);
        if (g < obstacles_[o].contact_gap) f(obstacles_[o], n.node, n.area, g);
      }
  }
  int dim_ = 2;
  Eigen::MatrixXd X_;  // reference coordinates
  std::vector<Obstacle> obstacles_;
  std::vector<std::vector<Node>> nodes_;  // per obstacle
  std::vector<int> excluded_;             // per obstacle
};

// The lumped measure of each node of the facets, size = number of mesh nodes. 2D: half of
// each edge; 3D bilinear quadrilaterals: int N_a dA. 6-node triangles: `Positive` (contact:
// every node needs a share) the HRZ shares of face_lumped_weights; `RowSum` (elastic supports:
// a uniform displacement then meets the same nodal distribution as a uniform traction) the
// consistent int N_a dA, 0 at the vertices of a flat face.
enum class FacetLumping { Positive, RowSum };
Eigen::VectorXd lumped_facet_measure(const SolidMesh& mesh, const std::vector<Facet>& facets,
                                     FacetLumping lumping = FacetLumping::Positive);

}  // namespace fsi::solid
