#include "fsi/solid/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "fsi/common/gmsh_reader.hpp"
#include "fsi/solid/element.hpp"

namespace fsi::solid {

std::vector<std::string> SolidMesh::facet_set_names() const {
  std::vector<std::string> names;
  for (const auto& [name, _] : facet_sets) names.push_back(name);
  return names;
}

std::vector<Facet> unique_facets(const std::vector<Facet>& facets) {
  std::vector<Facet> unique;
  std::set<std::vector<int>> seen;
  for (const auto& f : facets) {
    std::vector<int> key = f;
    std::sort(key.begin(), key.end());
    if (seen.insert(key).second) unique.push_back(f);
  }
  return unique;
}

std::vector<Eigen::MatrixXd> outward_area_vectors(const SolidMesh& mesh, const std::vector<Facet>& facets) {
  const int dim = mesh.dim;
  std::map<int, std::vector<int>> cells_of_node;
  for (int c = 0; c < mesh.num_cells(); ++c)
    for (int v : mesh.cells[static_cast<std::size_t>(c)]) cells_of_node[v].push_back(c);
  auto holder = [&](const Facet& f) {
    for (int c : cells_of_node[f[0]]) {
      const auto& cell = mesh.cells[static_cast<std::size_t>(c)];
      if (std::all_of(f.begin(), f.end(), [&](int v) { return std::find(cell.begin(), cell.end(), v) != cell.end(); }))
        return c;
    }
    return -1;
  };
  std::vector<Eigen::MatrixXd> out;
  out.reserve(facets.size());
  for (const auto& f : facets) {
    const int c = holder(f);
    if (c < 0) throw std::invalid_argument("a facet that is no cell's side");
    Eigen::VectorXd centre = Eigen::VectorXd::Zero(dim), facet_centre = Eigen::VectorXd::Zero(dim);
    for (int v : mesh.cells[static_cast<std::size_t>(c)]) centre += mesh.nodes.row(v).transpose();
    centre /= static_cast<double>(mesh.cells[static_cast<std::size_t>(c)].size());
    for (int v : f) facet_centre += mesh.nodes.row(v).transpose() / static_cast<double>(f.size());
    Eigen::MatrixXd a(f.size(), dim);  // int N_a n dA, per node
    if (dim == 2) {
      const Eigen::Vector2d t = mesh.nodes.row(f[1]) - mesh.nodes.row(f[0]);
      a.row(0) = a.row(1) = 0.5 * Eigen::RowVector2d(t.y(), -t.x());
    } else {
      Eigen::Matrix<double, 4, 3> X;
      for (int k = 0; k < 4; ++k) X.row(k) = mesh.nodes.row(f[static_cast<std::size_t>(k)]);
      a = quad_face_area_vectors(X);
    }
    if ((facet_centre - centre).dot(a.colwise().sum().transpose()) < 0) a = -a;
    out.push_back(std::move(a));
  }
  return out;
}

std::vector<Facet> SolidMesh::facets(const std::vector<std::string>& names) const {
  std::vector<Facet> out;
  for (const auto& name : names) {
    auto it = facet_sets.find(name);
    if (it == facet_sets.end()) {
      std::string known;
      for (const auto& n : facet_set_names()) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("no boundary named '" + name + "' in the mesh (known: " + known + ")");
    }
    out.insert(out.end(), it->second.begin(), it->second.end());
  }
  return out;
}

std::vector<int> SolidMesh::facet_nodes(const std::vector<std::string>& names) const {
  std::vector<int> out;
  std::set<int> seen;
  for (const auto& e : facets(names))
    for (int n : e)
      if (seen.insert(n).second) out.push_back(n);
  return out;
}

SolidMesh rectangle_mesh(double x0, double y0, double lx, double ly, int nx, int ny) {
  if (nx < 1 || ny < 1) throw std::invalid_argument("rectangle_mesh: need at least 1 x 1 elements");
  SolidMesh m;
  m.nodes.resize((nx + 1) * (ny + 1), 2);
  m.dim = 2;
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.nodes.row(id(i, j)) << x0 + lx * i / nx, y0 + ly * j / ny;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) m.cells.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  auto& bottom = m.facet_sets["bottom"];
  auto& top = m.facet_sets["top"];
  for (int i = 0; i < nx; ++i) {
    bottom.push_back({id(i, 0), id(i + 1, 0)});
    top.push_back({id(i + 1, ny), id(i, ny)});
  }
  auto& left = m.facet_sets["left"];
  auto& right = m.facet_sets["right"];
  for (int j = 0; j < ny; ++j) {
    right.push_back({id(nx, j), id(nx, j + 1)});
    left.push_back({id(0, j + 1), id(0, j)});
  }
  return m;
}

SolidMesh box_mesh(const Eigen::Vector3d& origin, const Eigen::Vector3d& size, int nx, int ny, int nz) {
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("box_mesh: need at least 1 x 1 x 1 elements");
  SolidMesh m;
  m.dim = 3;
  m.nodes.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
  auto id = [nx, ny](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        m.nodes.row(id(i, j, k)) << origin(0) + size(0) * i / nx, origin(1) + size(1) * j / ny,
            origin(2) + size(2) * k / nz;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        m.cells.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
                           id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
  // Faces counter-clockwise seen from outside (outward normal by the right-hand rule).
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      m.facet_sets["left"].push_back({id(0, j, k), id(0, j, k + 1), id(0, j + 1, k + 1), id(0, j + 1, k)});
      m.facet_sets["right"].push_back({id(nx, j, k), id(nx, j + 1, k), id(nx, j + 1, k + 1), id(nx, j, k + 1)});
    }
  for (int k = 0; k < nz; ++k)
    for (int i = 0; i < nx; ++i) {
      m.facet_sets["bottom"].push_back({id(i, 0, k), id(i + 1, 0, k), id(i + 1, 0, k + 1), id(i, 0, k + 1)});
      m.facet_sets["top"].push_back({id(i, ny, k), id(i, ny, k + 1), id(i + 1, ny, k + 1), id(i + 1, ny, k)});
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.facet_sets["back"].push_back({id(i, j, 0), id(i, j + 1, 0), id(i + 1, j + 1, 0), id(i + 1, j, 0)});
      m.facet_sets["front"].push_back({id(i, j, nz), id(i + 1, j, nz), id(i + 1, j + 1, nz), id(i, j + 1, nz)});
    }
  return m;
}

SolidMesh tube_mesh(const Eigen::Vector3d& origin, double r_inner, double r_outer, double length, int n_theta, int n_r,
                    int n_z) {
  if (n_theta < 3 || n_r < 1 || n_z < 1)
    throw std::invalid_argument("tube_mesh: need at least 3 cells around, 1 through the wall and 1 along");
  if (!(r_inner > 0 && r_outer > r_inner && length > 0))
    throw std::invalid_argument("tube_mesh: need 0 < inner radius < outer radius and a positive length");
  SolidMesh m;
  m.dim = 3;
  m.nodes.resize(static_cast<Eigen::Index>((n_r + 1) * n_theta * (n_z + 1)), 3);
  auto id = [n_r, n_theta](int i, int j, int k) { return (k * n_theta + (j % n_theta)) * (n_r + 1) + i; };
  const double pi = 3.14159265358979323846;
  for (int k = 0; k <= n_z; ++k)
    for (int j = 0; j < n_theta; ++j)
      for (int i = 0; i <= n_r; ++i) {
        const double r = r_inner + (r_outer - r_inner) * i / n_r, theta = 2 * pi * j / n_theta;
        m.nodes.row(id(i, j, k)) << origin(0) + r * std::cos(theta), origin(1) + r * std::sin(theta),
            origin(2) + length * k / n_z;
      }
  // (r, theta, z) is right-handed: the box's node order with x -> r, y -> theta, z -> z.
  for (int k = 0; k < n_z; ++k)
    for (int j = 0; j < n_theta; ++j)
      for (int i = 0; i < n_r; ++i)
        m.cells.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
                           id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
  for (int k = 0; k < n_z; ++k)
    for (int j = 0; j < n_theta; ++j) {
      m.facet_sets["inner"].push_back({id(0, j, k), id(0, j, k + 1), id(0, j + 1, k + 1), id(0, j + 1, k)});
      m.facet_sets["outer"].push_back({id(n_r, j, k), id(n_r, j + 1, k), id(n_r, j + 1, k + 1), id(n_r, j, k + 1)});
    }
  for (int j = 0; j < n_theta; ++j)
    for (int i = 0; i < n_r; ++i) {
      m.facet_sets["start"].push_back({id(i, j, 0), id(i, j + 1, 0), id(i + 1, j + 1, 0), id(i + 1, j, 0)});
      m.facet_sets["end"].push_back({id(i, j, n_z), id(i + 1, j, n_z), id(i + 1, j + 1, n_z), id(i, j + 1, n_z)});
    }
  return m;
}

void distort_interior(SolidMesh& mesh, double fraction, unsigned seed) {
  // Boundary nodes: those on any edge set.
  std::set<int> boundary;
  for (const auto& [_, facets] : mesh.facet_sets)
    for (const auto& e : facets) boundary.insert(e.begin(), e.end());
  double h = 1e300;
  for (const auto& c : mesh.cells)
    for (int a = 0; a < 4; ++a) h = std::min(h, (mesh.nodes.row(c[a]) - mesh.nodes.row(c[(a + 1) % 4])).norm());
  unsigned state = seed;
  auto next = [&state]() {  // LCG in [-1, 1]
    state = state * 1664525u + 1013904223u;
    return 2.0 * (state >> 8) / double(1u << 24) - 1.0;
  };
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const double dx = next(), dy = next(), dz = mesh.dim == 3 ? next() : 0.0;
    if (boundary.count(n)) continue;
    mesh.nodes(n, 0) += fraction * h * dx;
    mesh.nodes(n, 1) += fraction * h * dy;
    if (mesh.dim == 3) mesh.nodes(n, 2) += fraction * h * dz;
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
    auto& set = m.facet_sets[g.name];
    for (Eigen::Index e = 0; e < g.elements.rows(); ++e) {
      const int a = g.elements(e, 0), b = g.elements(e, 1);
      if (renumber.at(a) < 0 || renumber.at(b) < 0)
        throw std::invalid_argument("gmsh group '" + g.name + "' has an edge off the solid cells");
      set.push_back({renumber[a], renumber[b]});
    }
  }
  m.dim = 2;
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
