#include "fsi/fluid/mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace fsi::fluid {

const IndexMatrix2& FluidMesh::boundary(const std::string& name) const {
  const auto it = boundaries.find(name);
  if (it != boundaries.end()) return it->second;
  std::string known;
  for (const auto& [n, _] : boundaries) known += (known.empty() ? "" : ", ") + n;
  throw std::runtime_error(fmt::format("fluid mesh has no boundary group '{}' (groups: {})", name,
                                       known.empty() ? "none" : known));
}

std::vector<int> FluidMesh::boundary_nodes(const std::vector<std::string>& names) const {
  std::vector<int> result;
  for (const auto& name : names) {
    const auto& seg = boundary(name);
    for (Eigen::Index e = 0; e < seg.rows(); ++e) {
      result.push_back(seg(e, 0));
      result.push_back(seg(e, 1));
    }
  }
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

FluidMesh FluidMesh::from_gmsh(const GmshMesh& mesh, const std::vector<std::string>& domain_groups) {
  std::vector<const GmshGroup*> cells;
  for (const auto& g : mesh.groups) {
    if (g.dimension != 2) continue;
    if (!domain_groups.empty() && std::find(domain_groups.begin(), domain_groups.end(), g.name) == domain_groups.end())
      continue;
    if (g.element_type != 2)
      throw std::runtime_error(fmt::format("{}: group '{}' has gmsh element type {}; the P1/P1 fluid needs 3-node "
                                           "triangles (mesh with -order 1 and without recombination)",
                                           mesh.source.string(), g.name, g.element_type));
    cells.push_back(&g);
  }
  if (cells.empty()) throw std::runtime_error(fmt::format("{}: no 2D triangle group for the fluid", mesh.source.string()));

  std::vector<int> new_index(static_cast<std::size_t>(mesh.nodes.rows()), -1);
  int count = 0;
  Eigen::Index ntri = 0;
  for (const auto* g : cells) ntri += g->elements.rows();
  FluidMesh out;
  out.triangles.resize(ntri, 3);
  Eigen::Index t = 0;
  for (const auto* g : cells)
    for (Eigen::Index e = 0; e < g->elements.rows(); ++e, ++t)
      for (int k = 0; k < 3; ++k) {
        int& idx = new_index[static_cast<std::size_t>(g->elements(e, k))];
        if (idx < 0) idx = count++;
        out.triangles(t, k) = idx;
      }
  out.nodes.resize(count, 2);
  for (Eigen::Index i = 0; i < mesh.nodes.rows(); ++i)
    if (new_index[static_cast<std::size_t>(i)] >= 0) out.nodes.row(new_index[static_cast<std::size_t>(i)]) = mesh.nodes.row(i);
  for (Eigen::Index e = 0; e < out.triangles.rows(); ++e) {
    const Eigen::Vector2d a = out.nodes.row(out.triangles(e, 0)), b = out.nodes.row(out.triangles(e, 1)),
                          c = out.nodes.row(out.triangles(e, 2));
    const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (det < 0) std::swap(out.triangles(e, 1), out.triangles(e, 2));
    if (det == 0) throw std::runtime_error(fmt::format("{}: degenerate triangle {}", mesh.source.string(), e));
  }
  for (const auto& g : mesh.groups) {
    if (g.dimension != 1) continue;
    if (g.element_type != 1)
      throw std::runtime_error(fmt::format("{}: boundary group '{}' has gmsh element type {}; expected 2-node lines",
                                           mesh.source.string(), g.name, g.element_type));
    IndexMatrix2 seg(g.elements.rows(), 2);
    for (Eigen::Index e = 0; e < g.elements.rows(); ++e)
      for (int k = 0; k < 2; ++k) {
        const int idx = new_index[static_cast<std::size_t>(g.elements(e, k))];
        if (idx < 0)
          throw std::runtime_error(fmt::format("{}: boundary group '{}' has a node outside the fluid triangles",
                                               mesh.source.string(), g.name));
        seg(e, k) = idx;
      }
    out.boundaries[g.name] = std::move(seg);
  }
  return out;
}

FluidMesh FluidMesh::rectangle(double x0, double x1, double y0, double y1, int nx, int ny) {
  FluidMesh out;
  out.nodes.resize((nx + 1) * (ny + 1), 2);
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      out.nodes.row(id(i, j)) << x0 + (x1 - x0) * i / nx, y0 + (y1 - y0) * j / ny;
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
