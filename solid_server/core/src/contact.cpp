#include "fsi/solid/contact.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "fsi/solid/element.hpp"

namespace fsi::solid {

double contact_pressure(const Obstacle& o, double g) {
  if (!(g < o.contact_gap)) return 0;
  const double s = o.contact_gap - g;
  return o.stiffness * s * s / o.contact_gap;
}

double contact_pressure_derivative(const Obstacle& o, double g) {
  if (!(g < o.contact_gap)) return 0;
  return -2 * o.stiffness * (o.contact_gap - g) / o.contact_gap;
}

Eigen::VectorXd lumped_facet_measure(const SolidMesh& mesh, const std::vector<Facet>& facets, FacetLumping lumping) {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.num_nodes());
  for (const auto& f : facets) {
    if (mesh.dim == 2) {
      const double L = (mesh.nodes.row(f[0]) - mesh.nodes.row(f[1])).norm();
      for (int n : f) m(n) += 0.5 * L;
    } else {  // bilinear quadrilaterals: int N_a dA; 6-node triangles: HRZ or int N_a dA
      Eigen::MatrixXd X(f.size(), 3);
      for (std::size_t a = 0; a < f.size(); ++a) X.row(static_cast<Eigen::Index>(a)) = mesh.nodes.row(f[a]);
      const Eigen::VectorXd w = lumping == FacetLumping::Positive ? face_lumped_weights(X) : face_weights(X);
      for (std::size_t a = 0; a < f.size(); ++a) m(f[a]) += w(static_cast<Eigen::Index>(a));
    }
  }
  return m;
}

ObstacleContact::ObstacleContact(const SolidMesh& mesh, std::vector<Obstacle> obstacles,
                                 const std::vector<std::vector<Facet>>& facets, const std::vector<char>& fixed)
    : dim_(mesh.dim), X_(mesh.nodes), obstacles_(std::move(obstacles)) {
  if (facets.size() != obstacles_.size()) throw std::invalid_argument("ObstacleContact: one facet list per obstacle");
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(fixed.size()));
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const Eigen::VectorXd area = lumped_facet_measure(mesh, facets[i]);
    Obstacle& o = obstacles_[i];
    if (o.point.size() != dim_ || o.normal.size() != dim_)
      throw ObstacleError(static_cast<int>(i), fmt::format("point and normal need {} components", dim_));
    if (!(o.normal.norm() > 0)) throw ObstacleError(static_cast<int>(i), "the normal is zero");
    if (!(o.contact_gap > 0) || !(o.stiffness > 0))
      throw ObstacleError(static_cast<int>(i), "the contact gap and stiffness must be > 0");
    o.normal.normalize();
    std::vector<Node> nodes;
    int excluded = 0;
    for (int n = 0; n < mesh.num_nodes(); ++n) {
      if (!(area(n) > 0)) continue;
      bool all_fixed = true;
      for (int c = 0; c < dim_; ++c) all_fixed = all_fixed && fixed[static_cast<std::size_t>(dim_ * n + c)];
      const double g = gap(o, n, zero);
      if (g < 0 && !all_fixed) {
        std::string at;
        for (int c = 0; c < dim_; ++c) at += fmt::format("{}{:.6g}", c ? ", " : "", X_(n, c));
        throw ObstacleError(static_cast<int>(i),
                            fmt::format("puts the obstacle over the solid's boundary node {} at ({}) (gap {:.3g} < "
                                        "0): the solid must start outside every obstacle",
                                        n, at, g));
      }
      if (all_fixed) continue;
      if (g < o.contact_gap) {
        ++excluded;
        continue;
      }
      nodes.push_back({n, area(n)});
    }
    nodes_.push_back(std::move(nodes));
    excluded_.push_back(excluded);
  }
}

void ObstacleContact::add_to_residual(const Eigen::VectorXd& d, Eigen::VectorXd& r) const {
  for_each_active(d, [&](const Obstacle& o, int node, double area, double g) {
    r.segment(dim_ * node, dim_) -= area * contact_pressure(o, g) * o.normal;
  });
}

ContactState ObstacleContact::measure(const Eigen::VectorXd& d) const {
  ContactState s;
  s.force = Eigen::VectorXd::Zero(dim_);
  for (std::size_t o = 0; o < obstacles_.size(); ++o)
    for (const Node& n : nodes_[o]) {
      const double g = gap(obstacles_[o], n.node, d);
      const Eigen::VectorXd x = X_.row(n.node).transpose() + d.segment(dim_ * n.node, dim_);
      if (g < s.min_gap) s.min_gap = g, s.min_gap_point = x;
      if (!(g < obstacles_[o].contact_gap)) continue;
      ++s.active_nodes;
      s.force += n.area * contact_pressure(obstacles_[o], g) * obstacles_[o].normal;
      if (s.lower.size() == 0)
        s.lower = s.upper = x;
      else
        s.lower = s.lower.cwiseMin(x), s.upper = s.upper.cwiseMax(x);
    }
  return s;
}

}  // namespace fsi::solid
