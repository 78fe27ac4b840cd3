#include "fsi/solid/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "fsi/common/gmsh_reader.hpp"

namespace fsi::solid {

std::vector<std::string> SolidMesh::edge_set_names() const {
  std::vector<std::string> names;
  for (const auto& [name, _] : edge_sets) names.push_back(name);
  return names;
}

std::vector<std::array<int, 2>> SolidMesh::edges(const std::vector<std::string>& names) const {
  std::vector<std::array<int, 2>> out;
  for (const auto& name : names) {
    auto it = edge_sets.find(name);
    if (it == edge_sets.end()) {
      std::string known;
      for (const auto& n : edge_set_names()) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("no boundary named '" + name + "' in the mesh (known: " + known + ")");
    }
    out.insert(out.end(), it->second.begin(), it->second.end());
  }
  return out;
}

std::vector<int> SolidMesh::edge_nodes(const std::vector<std::string>& names) const {
  std::vector<int> out;
  std::set<int> seen;
  for (const auto& e : edges(names))
    for (int n : e)
      if (seen.insert(n).second) out.push_back(n);
  return out;
}

SolidMesh rectangle_mesh(double x0, double y0, double lx, double ly, int nx, int ny) {
  if (nx < 1 || ny < 1) throw std::invalid_argument("rectangle_mesh: need at least 1 x 1 elements");
  SolidMesh m;
  m.nodes.resize((nx + 1) * (ny + 1), 2);
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.nodes.row(id(i, j)) << x0 + lx * i / nx, y0 + ly * j / ny;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) m.cells.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  auto& bottom = m.edge_sets["bottom"];
  auto& top = m.edge_sets["top"];
  for (int i = 0; i < nx; ++i) {
    bottom.push_back({id(i, 0), id(i + 1, 0)});
    top.push_back({id(i + 1, ny), id(i, ny)});
  }
  auto& left = m.edge_sets["left"];
  auto& right = m.edge_sets["right"];
  for (int j = 0; j < ny; ++j) {
    right.push_back({id(nx, j), id(nx, j + 1)});
    left.push_back({id(0, j + 1), id(0, j)});
  }
  return m;
}

void distort_interior(SolidMesh& mesh, double fraction, unsigned seed) {
  // Boundary nodes: those on any edge set.
  std::set<int> boundary;
  for (const auto& [_, edges] : mesh.edge_sets)
    for (const auto& e : edges) boundary.insert(e.begin(), e.end());
  double h = 1e300;
  for (const auto& c : mesh.cells)
    for (int a = 0; a < 4; ++a) h = std::min(h, (mesh.nodes.row(c[a]) - mesh.nodes.row(c[(a + 1) % 4])).norm());
  unsigned state = seed;
  auto next = [&state]() {  // LCG in [-1, 1]
    state = state * 1664525u + 1013904223u;
    return 2.0 * (state >> 8) / double(1u << 24) - 1.0;
  };
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const double dx = next(), dy = next();
    if (boundary.count(n)) continue;
    mesh.nodes(n, 0) += fraction * h * dx;
    mesh.nodes(n, 1) += fraction * h * dy;
  }
}

SolidMesh mesh_from_gmsh(const GmshMesh& gmsh, const std::string& domain) {
  SolidMesh m;
  std::vector<int> renumber(gmsh.nodes.rows(), -1);
  int count = 0;
  auto use = [&](int n) {
    if (n < 0 || n >= static_cast<int>(renumber.size()))
      throw std::invalid_argument("gmsh mesh: node index out of range");
    if (renumber[n] < 0) renumber[n] = count++;
    return renumber[n];
  };
  bool found = false;
  for (const auto& g : gmsh.groups) {
    if (g.dimension != 2 || (!domain.empty() && g.name != domain)) continue;
    if (g.element_type != 3)
      throw std::invalid_argument("gmsh group '" + g.name +
                                  "': only 4-node quadrilaterals (type 3) are supported, got type " +
                                  std::to_string(g.element_type));
    found = true;
    for (Eigen::Index e = 0; e < g.elements.rows(); ++e)
      m.cells.push_back({use(g.elements(e, 0)), use(g.elements(e, 1)), use(g.elements(e, 2)), use(g.elements(e, 3))});
  }
  if (!found)
    throw std::invalid_argument(domain.empty() ? std::string("gmsh mesh has no 2D quadrilateral group")
                                               : "gmsh mesh has no 2D group named '" + domain + "'");
  for (const auto& g : gmsh.groups) {
    if (g.dimension != 1) continue;
    if (g.element_type != 1)
      throw std::invalid_argument("gmsh group '" + g.name + "': only 2-node lines (type 1) are supported");
    auto& set = m.edge_sets[g.name];
    for (Eigen::Index e = 0; e < g.elements.rows(); ++e) {
      const int a = g.elements(e, 0), b = g.elements(e, 1);
      if (renumber.at(a) < 0 || renumber.at(b) < 0)
        throw std::invalid_argument("gmsh group '" + g.name + "' has an edge off the solid cells");
      set.push_back({renumber[a], renumber[b]});
    }
  }
  m.nodes.resize(count, 2);
  for (std::size_t n = 0; n < renumber.size(); ++n)
    if (renumber[n] >= 0) m.nodes.row(renumber[n]) = gmsh.nodes.row(static_cast<Eigen::Index>(n));
  for (auto& c : m.cells) {
    double area2 = 0;
    for (int a = 0; a < 4; ++a) {
      const auto p = m.nodes.row(c[a]), q = m.nodes.row(c[(a + 1) % 4]);
      area2 += p(0) * q(1) - q(0) * p(1);
    }
    if (area2 < 0) std::swap(c[1], c[3]);
  }
  return m;
}

}  // namespace fsi::solid
