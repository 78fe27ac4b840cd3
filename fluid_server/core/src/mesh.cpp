#include "fsi/fluid/mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <stdexcept>

namespace fsi::fluid {

const IndexMatrix2& FluidMesh::boundary(const std::string& name) const {
  const auto it = boundaries.find(name);
  if (it != boundaries.end()) return it->second;
  std::string known;
  for (const auto& [n, _] : boundaries) known += (known.empty() ? "" : ", ") + n;
  throw std::runtime_error(
      fmt::format("fluid mesh has no boundary group '{}' (groups: {})", name, known.empty() ? "none" : known));
}

std::vector<int> FluidMesh::boundary_nodes(const std::vector<std::string>& names) const {
  std::vector<int> result;
  for (const auto& name : names) {
    const auto& seg = boundary(name);
    for (Eigen::Index e = 0; e < seg.rows(); ++e) {
      result.push_back(seg(e, 0));
      result.push_back(seg(e, 1));
    }
    if (const auto it = boundary_midpoints.find(name); it != boundary_midpoints.end())
      for (Eigen::Index e = 0; e < it->second.size(); ++e) result.push_back(it->second(e));
  }
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

Eigen::Matrix<int, 6, 1> FluidMesh::element_nodes6(int e) const {
  Eigen::Matrix<int, 6, 1> n;
  n << triangles(e, 0), triangles(e, 1), triangles(e, 2), edge_nodes(e, 0), edge_nodes(e, 1), edge_nodes(e, 2);
  return n;
}

FluidMesh FluidMesh::from_gmsh(const GmshMesh& mesh, const std::vector<std::string>& domain_groups) {
  if (mesh.has_volume())
    throw std::runtime_error(
        fmt::format("{}: a 3D mesh (tetrahedra) for a 2D fluid (set fluid.dimension: 3)", mesh.source.string()));
  std::vector<const GmshGroup*> cells;
  int cell_type = 0;
  for (const auto& g : mesh.groups) {
    if (g.dimension != 2) continue;
    if (!domain_groups.empty() && std::find(domain_groups.begin(), domain_groups.end(), g.name) == domain_groups.end())
      continue;
    if (g.element_type != 2 && g.element_type != 9)
      throw std::runtime_error(
          fmt::format("{}: group '{}' has gmsh element type {}; the fluid needs 3-node (P1/P1) "
                      "or 6-node (P2/P1) triangles (mesh without recombination)",
                      mesh.source.string(), g.name, g.element_type));
    if (cell_type != 0 && g.element_type != cell_type)
      throw std::runtime_error(
          fmt::format("{}: the fluid groups mix 3-node and 6-node triangles", mesh.source.string()));
    cell_type = g.element_type;
    cells.push_back(&g);
  }
  if (cells.empty())
    throw std::runtime_error(fmt::format("{}: no 2D triangle group for the fluid", mesh.source.string()));
  const bool quad = cell_type == 9;

  std::vector<int> new_index(static_cast<std::size_t>(mesh.nodes.rows()), -1);
  int count = 0;
  Eigen::Index ntri = 0;
  for (const auto* g : cells) ntri += g->elements.rows();
  FluidMesh out;
  out.triangles.resize(ntri, 3);
  if (quad) out.edge_nodes.resize(ntri, 3);
  // Vertices first, then the midpoints (pressure unknowns live on the vertices).
  for (int pass = 0; pass < (quad ? 2 : 1); ++pass) {
    Eigen::Index t = 0;
    for (const auto* g : cells)
      for (Eigen::Index e = 0; e < g->elements.rows(); ++e, ++t)
        for (int k = 0; k < 3; ++k) {
          int& idx = new_index[static_cast<std::size_t>(g->elements(e, 3 * pass + k))];
          if (idx < 0) idx = count++;
          (pass == 0 ? out.triangles : out.edge_nodes)(t, k) = idx;
        }
    if (pass == 0) out.vertex_count = count;
  }
  if (!quad) out.vertex_count = -1;
  out.nodes.resize(count, 2);
  for (Eigen::Index i = 0; i < mesh.nodes.rows(); ++i)
    if (new_index[static_cast<std::size_t>(i)] >= 0)
      out.nodes.row(new_index[static_cast<std::size_t>(i)]) = mesh.nodes.row(i);
  for (Eigen::Index e = 0; e < out.triangles.rows(); ++e) {
    const Eigen::Vector2d a = out.nodes.row(out.triangles(e, 0)), b = out.nodes.row(out.triangles(e, 1)),
                          c = out.nodes.row(out.triangles(e, 2));
    const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (det == 0) throw std::runtime_error(fmt::format("{}: degenerate triangle {}", mesh.source.string(), e));
    if (det < 0) {
      std::swap(out.triangles(e, 1), out.triangles(e, 2));
      if (quad) std::swap(out.edge_nodes(e, 0), out.edge_nodes(e, 2));  // edges 01 <-> 20, 12 stays
    }
  }
  for (const auto& g : mesh.groups) {
    if (g.dimension != 1) continue;
    const int expected = quad ? 8 : 1;
    if (g.element_type != expected)
      throw std::runtime_error(fmt::format(
          "{}: boundary group '{}' has gmsh element type {}; expected {} lines with {} "
          "triangles",
          mesh.source.string(), g.name, g.element_type, quad ? "3-node" : "2-node", quad ? "6-node" : "3-node"));
    IndexMatrix2 seg(g.elements.rows(), 2);
    Eigen::VectorXi mid(quad ? g.elements.rows() : 0);
    for (Eigen::Index e = 0; e < g.elements.rows(); ++e)
      for (int k = 0; k < (quad ? 3 : 2); ++k) {
        const int idx = new_index[static_cast<std::size_t>(g.elements(e, k))];
        if (idx < 0)
          throw std::runtime_error(fmt::format("{}: boundary group '{}' has a node outside the fluid triangles",
                                               mesh.source.string(), g.name));
        if (k < 2)
          seg(e, k) = idx;
        else
          mid(e) = idx;
      }
    out.boundaries[g.name] = std::move(seg);
    if (quad) out.boundary_midpoints[g.name] = std::move(mid);
  }
  return out;
}

FluidMesh FluidMesh::quadratic_from_linear() const {
  if (quadratic()) return *this;
  FluidMesh out;
  out.triangles = triangles;
  out.boundaries = boundaries;
  out.vertex_count = node_count();
  out.edge_nodes.resize(triangle_count(), 3);
  std::map<std::pair<int, int>, int> edge_index;
  std::vector<Eigen::RowVector2d> extra;
  auto midpoint = [&](int a, int b) {
    const auto key = std::make_pair(std::min(a, b), std::max(a, b));
    auto [it, inserted] = edge_index.emplace(key, node_count() + static_cast<int>(extra.size()));
    if (inserted) extra.push_back(0.5 * (nodes.row(a) + nodes.row(b)));
    return it->second;
  };
  for (int e = 0; e < triangle_count(); ++e)
    for (int k = 0; k < 3; ++k) out.edge_nodes(e, k) = midpoint(triangles(e, k), triangles(e, (k + 1) % 3));
  for (const auto& [name, seg] : boundaries) {
    Eigen::VectorXi mid(seg.rows());
    for (Eigen::Index s = 0; s < seg.rows(); ++s) {
      const auto it = edge_index.find({std::min(seg(s, 0), seg(s, 1)), std::max(seg(s, 0), seg(s, 1))});
      if (it == edge_index.end())
        throw std::runtime_error(
            fmt::format("boundary group '{}': segment ({}, {}) is not a triangle edge", name, seg(s, 0), seg(s, 1)));
      mid(s) = it->second;
    }
    out.boundary_midpoints[name] = std::move(mid);
  }
  out.nodes.resize(node_count() + static_cast<Eigen::Index>(extra.size()), 2);
  out.nodes.topRows(node_count()) = nodes;
  for (std::size_t i = 0; i < extra.size(); ++i) out.nodes.row(node_count() + static_cast<Eigen::Index>(i)) = extra[i];
  return out;
}

FluidMesh FluidMesh::linear_refinement() const {
  if (!quadratic()) return *this;
  FluidMesh out;
  out.nodes = nodes;
  out.triangles.resize(4 * triangle_count(), 3);
  for (int e = 0; e < triangle_count(); ++e) {
    const auto n = element_nodes6(e);
    out.triangles.row(4 * e + 0) << n(0), n(3), n(5);
    out.triangles.row(4 * e + 1) << n(3), n(1), n(4);
    out.triangles.row(4 * e + 2) << n(5), n(4), n(2);
    out.triangles.row(4 * e + 3) << n(3), n(4), n(5);
  }
  for (const auto& [name, seg] : boundaries) {
    const auto& mid = boundary_midpoints.at(name);
    IndexMatrix2 split(2 * seg.rows(), 2);
    for (Eigen::Index s = 0; s < seg.rows(); ++s) {
      split.row(2 * s) << seg(s, 0), mid(s);
      split.row(2 * s + 1) << mid(s), seg(s, 1);
    }
    out.boundaries[name] = std::move(split);
  }
  return out;
}

FluidMesh FluidMesh::rectangle(double x0, double x1, double y0, double y1, int nx, int ny) {
  FluidMesh out;
  out.nodes.resize((nx + 1) * (ny + 1), 2);
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) out.nodes.row(id(i, j)) << x0 + (x1 - x0) * i / nx, y0 + (y1 - y0) * j / ny;
  out.triangles.resize(2 * nx * ny, 3);
  int t = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0) {
        out.triangles.row(t++) << a, b, c;
        out.triangles.row(t++) << a, c, d;
      } else {
        out.triangles.row(t++) << a, b, d;
        out.triangles.row(t++) << b, c, d;
      }
    }
  IndexMatrix2 bottom(nx, 2), top(nx, 2), left(ny, 2), right(ny, 2);
  for (int i = 0; i < nx; ++i) {
    bottom.row(i) << id(i, 0), id(i + 1, 0);
    top.row(i) << id(i + 1, ny), id(i, ny);
  }
  for (int j = 0; j < ny; ++j) {
    left.row(j) << id(0, j + 1), id(0, j);
    right.row(j) << id(nx, j), id(nx, j + 1);
  }
  out.boundaries = {{"bottom", bottom}, {"top", top}, {"left", left}, {"right", right}};
  return out;
}

}  // namespace fsi::fluid
