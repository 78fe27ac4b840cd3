#include "fsi/solid/elastic_support.hpp"

#include <fmt/format.h>

#include <map>
#include <stdexcept>

#include "fsi/solid/contact.hpp"

namespace fsi::solid {

ElasticSupport::ElasticSupport(const SolidMesh& mesh, const std::vector<SupportSpec>& supports) : dim_(mesh.dim) {
  std::map<int, Eigen::MatrixXd> k;
  for (std::size_t s = 0; s < supports.size(); ++s) {
    const SupportSpec& spec = supports[s];
    if (!(spec.stiffness > 0))
      throw std::invalid_argument(fmt::format("elastic support {}: the stiffness must be > 0", s));
    // int N_a dA (0 at the vertices of a flat 6-node triangle, whose int N_a n0 dA is 0 too).
    const Eigen::VectorXd area = lumped_facet_measure(mesh, spec.facets, FacetLumping::RowSum);
    // The node's outward normal: the sum of its facets' int N_a n0 dA (outward_area_vectors).
    Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(mesh.num_nodes(), dim_);
    std::vector<Eigen::MatrixXd> vectors;
    try {
      vectors = outward_area_vectors(mesh, spec.facets);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("elastic support {}: {}", s, e.what()));
    }
    for (std::size_t i = 0; i < spec.facets.size(); ++i)
      for (std::size_t a = 0; a < spec.facets[i].size(); ++a)
        normal.row(spec.facets[i][a]) += vectors[i].row(static_cast<Eigen::Index>(a));
    for (int a = 0; a < mesh.num_nodes(); ++a) {
      if (!(area(a) > 0)) continue;
      Eigen::MatrixXd block = spec.stiffness * area(a) * Eigen::MatrixXd::Identity(dim_, dim_);
      if (spec.normal_only) {
        const Eigen::VectorXd n = normal.row(a).transpose().normalized();
        block = spec.stiffness * area(a) * n * n.transpose();
      }
      auto [it, fresh] = k.try_emplace(a, block);
      if (!fresh) it->second += block;
    }
  }
  for (auto& [node, block] : k) nodes_.push_back({node, block});
}

void ElasticSupport::add_to_residual(const Eigen::VectorXd& d, Eigen::VectorXd& r) const {
  for (const Node& n : nodes_) r.segment(dim_ * n.node, dim_) += n.k * d.segment(dim_ * n.node, dim_);
}

Eigen::VectorXd ElasticSupport::force(const Eigen::VectorXd& d) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dim_);
  for (const Node& n : nodes_) f -= n.k * d.segment(dim_ * n.node, dim_);
  return f;
}

}  // namespace fsi::solid
