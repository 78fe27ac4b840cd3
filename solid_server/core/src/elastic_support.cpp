#include "fsi/solid/elastic_support.hpp"

#include <fmt/format.h>

#include <map>
#include <stdexcept>

#include "fsi/solid/contact.hpp"

namespace fsi::solid {

namespace {

// The facet's normal with the length of its measure (2D: the edge's length; 3D: the
// quadrilateral's area), pointing away from `inside` (a point of its cell).
Eigen::VectorXd scaled_normal(const SolidMesh& mesh, const Facet& f, const Eigen::VectorXd& inside) {
  Eigen::VectorXd n(mesh.dim), centre = Eigen::VectorXd::Zero(mesh.dim);
  for (int a : f) centre += mesh.nodes.row(a).transpose();
  centre /= static_cast<double>(f.size());
  if (mesh.dim == 2) {
    const Eigen::Vector2d t = (mesh.nodes.row(f[1]) - mesh.nodes.row(f[0])).transpose();
    n << t.y(), -t.x();
  } else {
    const Eigen::Vector3d d1 = (mesh.nodes.row(f[2]) - mesh.nodes.row(f[0])).transpose();
    const Eigen::Vector3d d2 = (mesh.nodes.row(f[3]) - mesh.nodes.row(f[1])).transpose();
    n = 0.5 * d1.cross(d2);
  }
  if (n.dot(centre - inside) < 0) n = -n;
  return n;
}

}  // namespace

ElasticSupport::ElasticSupport(const SolidMesh& mesh, const std::vector<SupportSpec>& supports) : dim_(mesh.dim) {
  // A point inside the cell of each boundary node's facets: the centroid of a cell holding
  // every node of the facet.
  std::vector<std::vector<int>> cells_of(static_cast<std::size_t>(mesh.num_nodes()));
  for (int c = 0; c < mesh.num_cells(); ++c)
    for (int a : mesh.cells[static_cast<std::size_t>(c)]) cells_of[static_cast<std::size_t>(a)].push_back(c);
  std::map<int, Eigen::MatrixXd> k;
  for (std::size_t s = 0; s < supports.size(); ++s) {
    const SupportSpec& spec = supports[s];
    if (!(spec.stiffness > 0))
      throw std::invalid_argument(fmt::format("elastic support {}: the stiffness must be > 0", s));
    const Eigen::VectorXd area = lumped_facet_measure(mesh, spec.facets);
    Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(mesh.num_nodes(), dim_);  // area-weighted, per node
    for (const Facet& f : spec.facets) {
      int owner = -1;
      for (int c : cells_of[static_cast<std::size_t>(f[0])]) {
        const auto& cell = mesh.cells[static_cast<std::size_t>(c)];
        bool all = true;
        for (int a : f) all = all && std::find(cell.begin(), cell.end(), a) != cell.end();
        if (all) owner = c;
      }
      if (owner < 0) throw std::invalid_argument(fmt::format("elastic support {}: a facet of no cell", s));
      Eigen::VectorXd inside = Eigen::VectorXd::Zero(dim_);
      for (int a : mesh.cells[static_cast<std::size_t>(owner)]) inside += mesh.nodes.row(a).transpose();
      inside /= static_cast<double>(mesh.cells[static_cast<std::size_t>(owner)].size());
      const Eigen::VectorXd n = scaled_normal(mesh, f, inside);
      for (int a : f) normal.row(a) += n.transpose();
    }
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
