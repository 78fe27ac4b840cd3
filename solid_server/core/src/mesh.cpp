#include "fsi/solid/mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <stdexcept>

#include "fsi/common/gmsh_reader.hpp"
#include "fsi/solid/element.hpp"

namespace fsi::solid {

const char* cell_kind_name(CellKind kind) {
  switch (kind) {
    case CellKind::Quad4:
      return "quadrilateral (Q4)";
    case CellKind::Hex8:
      return "hexahedron (Hex8)";
    case CellKind::Tet10:
      return "quadratic tetrahedron (Tet10)";
  }
  return "?";
}

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
      Eigen::MatrixXd X(f.size(), 3);
      for (std::size_t k = 0; k < f.size(); ++k) X.row(static_cast<Eigen::Index>(k)) = mesh.nodes.row(f[k]);
      a = face_area_vectors(X);
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
  m.cell = CellKind::Hex8;
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
  m.cell = CellKind::Hex8;
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

namespace {
// Adds the edge midpoints of tetrahedra given by their 4 vertices (nodes 0 .. vertices - 1 of
// `nodes`, straight edges): returns the Tet10 cells, with midpoint nodes appended to `nodes`.
std::vector<std::vector<int>> tet10_from_vertices(const std::vector<std::array<int, 4>>& tets,
                                                  std::vector<Eigen::Vector3d>& nodes) {
  constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {2, 3}, {1, 3}};
  std::map<std::pair<int, int>, int> midpoint;
  std::vector<std::vector<int>> cells;
  for (const auto& t : tets) {
    std::vector<int> cell(t.begin(), t.end());
    for (const auto& e : kEdges) {
      const int a = t[static_cast<std::size_t>(e[0])], b = t[static_cast<std::size_t>(e[1])];
      auto [it, fresh] = midpoint.try_emplace({std::min(a, b), std::max(a, b)}, static_cast<int>(nodes.size()));
      if (fresh) nodes.push_back(0.5 * (nodes[static_cast<std::size_t>(a)] + nodes[static_cast<std::size_t>(b)]));
      cell.push_back(it->second);
    }
    cells.push_back(std::move(cell));
  }
  return cells;
}
}  // namespace

SolidMesh box_tet_mesh(const Eigen::Vector3d& origin, const Eigen::Vector3d& size, int nx, int ny, int nz) {
  const SolidMesh hex = box_mesh(origin, size, nx, ny, nz);
  std::vector<Eigen::Vector3d> nodes;
  for (int n = 0; n < hex.num_nodes(); ++n) nodes.emplace_back(hex.nodes.row(n).transpose());
  // Kuhn: the cube's 6 paths from corner (0,0,0) to (1,1,1) along the axes, one per axis order.
  auto id = [nx, ny](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  std::vector<std::array<int, 4>> tets;
  const int orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& order : orders) {
          std::array<int, 3> p = {i, j, k};
          std::array<int, 4> t{};
          t[0] = id(p[0], p[1], p[2]);
          for (int s = 0; s < 3; ++s) {
            ++p[static_cast<std::size_t>(order[s])];
            t[static_cast<std::size_t>(s + 1)] = id(p[0], p[1], p[2]);
          }
          Eigen::Matrix3d J;
          for (int c = 0; c < 3; ++c)
            J.col(c) = nodes[static_cast<std::size_t>(t[static_cast<std::size_t>(c + 1)])] -
                       nodes[static_cast<std::size_t>(t[0])];
          if (J.determinant() < 0) std::swap(t[1], t[2]);
          tets.push_back(t);
        }
  SolidMesh m;
  m.dim = 3;
  m.cell = CellKind::Tet10;
  m.cells = tet10_from_vertices(tets, nodes);
  m.nodes.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for (std::size_t n = 0; n < nodes.size(); ++n) m.nodes.row(static_cast<Eigen::Index>(n)) = nodes[n].transpose();
  // Boundary faces: the tetrahedra's faces whose three vertices lie on one side of the box.
  const Eigen::Vector3d lo = origin, hi = origin + size;
  const double tol = 1e-12 * size.maxCoeff();
  const std::array<std::pair<const char*, std::pair<int, bool>>, 6> sides = {{{"left", {0, false}},
                                                                              {"right", {0, true}},
                                                                              {"bottom", {1, false}},
                                                                              {"top", {1, true}},
                                                                              {"back", {2, false}},
                                                                              {"front", {2, true}}}};
  for (const auto& [name, side] : sides) m.facet_sets[name];
  for (const auto& cell : m.cells)
    for (const auto& face : Tet10::faces()) {
      for (const auto& [name, side] : sides) {
        const auto [axis, upper] = side;
        const double plane = upper ? hi(axis) : lo(axis);
        bool on = true;
        for (int v = 0; v < 3; ++v)
          on = on && std::abs(m.nodes(cell[static_cast<std::size_t>(face[static_cast<std::size_t>(v)])], axis) -
                              plane) <= tol;
        if (!on) continue;
        Facet f;
        for (int v : face) f.push_back(cell[static_cast<std::size_t>(v)]);
        m.facet_sets[name].push_back(std::move(f));
      }
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

namespace {

// Faces of a Hex8 cell (VTK order), right-handed outward.
constexpr int kHexFaces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

std::vector<int> sorted(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  return v;
}

SolidMesh mesh_from_gmsh_3d(const GmshMesh& gmsh, const std::string& domain) {
  SolidMesh m;
  m.dim = 3;
  std::vector<int> renumber(static_cast<std::size_t>(gmsh.nodes.rows()), -1);
  int count = 0;
  auto use = [&](int n) {
    if (n < 0 || n >= static_cast<int>(renumber.size()))
      throw std::invalid_argument("gmsh mesh: node index out of range");
    if (renumber[static_cast<std::size_t>(n)] < 0) renumber[static_cast<std::size_t>(n)] = count++;
    return renumber[static_cast<std::size_t>(n)];
  };
  auto point = [&](int n) {
    const auto k = static_cast<Eigen::Index>(n);
    return Eigen::Vector3d(gmsh.nodes(k, 0), gmsh.nodes(k, 1), gmsh.z.size() > k ? gmsh.z(k) : 0.0);
  };
  int cell_type = 0;
  std::vector<std::pair<std::string, int>> origin;  // group and element number of each cell
  for (const auto& g : gmsh.groups) {
    if (g.dimension != 3 || (!domain.empty() && g.name != domain)) continue;
    if (g.element_type != 11 && g.element_type != 5)
      throw std::invalid_argument("gmsh group '" + g.name +
                                  "': the 3D solid takes 10-node tetrahedra (type 11) or 8-node hexahedra (type 5), "
                                  "got type " +
                                  std::to_string(g.element_type) +
                                  (g.element_type == 4 ? " (4-node tetrahedra: mesh with gmsh -order 2)" : ""));
    if (cell_type != 0 && cell_type != g.element_type)
      throw std::invalid_argument("gmsh group '" + g.name +
                                  "': one cell type per solid mesh (tetrahedra or hexahedra)");
    cell_type = g.element_type;
    for (Eigen::Index e = 0; e < g.elements.rows(); ++e) {
      std::vector<int> raw(static_cast<std::size_t>(g.elements.cols()));
      for (Eigen::Index a = 0; a < g.elements.cols(); ++a) raw[static_cast<std::size_t>(a)] = g.elements(e, a);
      if (cell_type == 11) {
        Eigen::Matrix3d J;
        for (int c = 0; c < 3; ++c) J.col(c) = point(raw[static_cast<std::size_t>(c + 1)]) - point(raw[0]);
        // Mirrored: swap vertices 1 and 2, so edges 0-1 <-> 0-2 (nodes 4, 6) and 1-3 <-> 2-3 (9, 8).
        if (J.determinant() < 0) std::swap(raw[1], raw[2]), std::swap(raw[4], raw[6]), std::swap(raw[8], raw[9]);
      } else {
        const Eigen::Vector3d c0 = point(raw[0]);
        const double orient = (point(raw[1]) - c0).cross(point(raw[3]) - c0).dot(point(raw[4]) - c0);
        if (orient < 0) raw = {raw[0], raw[3], raw[2], raw[1], raw[4], raw[7], raw[6], raw[5]};
      }
      std::vector<int> cell;
      for (int v : raw) cell.push_back(use(v));
      m.cells.push_back(std::move(cell));
      origin.emplace_back(g.name, static_cast<int>(e));
    }
  }
  if (cell_type == 0)
    throw std::invalid_argument(domain.empty() ? std::string("gmsh mesh has no 3D group")
                                               : "gmsh mesh has no 3D group named '" + domain + "'");
  m.cell = cell_type == 11 ? CellKind::Tet10 : CellKind::Hex8;
  const int facet_type = cell_type == 11 ? 9 : 3;
  m.nodes.resize(count, 3);
  for (std::size_t n = 0; n < renumber.size(); ++n)
    if (renumber[n] >= 0) m.nodes.row(renumber[n]) = point(static_cast<int>(n)).transpose();
  // Every cell's map must be positive at its Gauss points (a tangled curved tetrahedron is not).
  with_shape(m.cell, [&](auto shape) {
    using Shape = decltype(shape);
    for (std::size_t c = 0; c < m.cells.size(); ++c) {
      typename ElementTraits<Shape>::Coords X;
      for (int a = 0; a < Shape::nodes; ++a) X.row(a) = m.nodes.row(m.cells[c][static_cast<std::size_t>(a)]);
      for (const auto& [xi, w] : Shape::gauss())
        if (!((X.transpose() * Shape::derivatives(xi)).determinant() > 0))
          throw std::invalid_argument("gmsh group '" + origin[c].first + "', element " +
                                      std::to_string(origin[c].second + 1) +
                                      ": inverted or degenerate cell (det J <= 0 at a Gauss point)");
    }
  });
  // The cells' sides, to check the facets.
  std::set<std::vector<int>> sides;
  for (const auto& cell : m.cells) {
    if (m.cell == CellKind::Tet10) {
      for (const auto& face : Tet10::faces()) {
        std::vector<int> f;
        for (int v : face) f.push_back(cell[static_cast<std::size_t>(v)]);
        sides.insert(sorted(f));
      }
    } else {
      for (const auto& face : kHexFaces) {
        std::vector<int> f;
        for (int v : face) f.push_back(cell[static_cast<std::size_t>(v)]);
        sides.insert(sorted(f));
      }
    }
  }
  for (const auto& g : gmsh.groups) {
    if (g.dimension != 2) continue;
    if (g.element_type != facet_type)
      throw std::invalid_argument("gmsh group '" + g.name + "': the facets of a " +
                                  (cell_type == 11 ? "10-node tetrahedron mesh are 6-node triangles (type 9)"
                                                   : "hexahedron mesh are 4-node quadrilaterals (type 3)") +
                                  ", got type " + std::to_string(g.element_type));
    auto& set = m.facet_sets[g.name];
    for (Eigen::Index e = 0; e < g.elements.rows(); ++e) {
      Facet f;
      for (Eigen::Index a = 0; a < g.elements.cols(); ++a) {
        const int n = g.elements(e, a);
        f.push_back(n >= 0 && n < static_cast<int>(renumber.size()) ? renumber[static_cast<std::size_t>(n)] : -1);
      }
      if (std::find(f.begin(), f.end(), -1) != f.end() || !sides.count(sorted(f)))
        throw std::invalid_argument("gmsh group '" + g.name + "', element " + std::to_string(e + 1) +
                                    ": a facet that is no side of a solid cell");
      set.push_back(std::move(f));
    }
  }
  return m;
}

}  // namespace

SolidMesh mesh_from_gmsh(const GmshMesh& gmsh, const std::string& domain) {
  if (gmsh.has_volume()) return mesh_from_gmsh_3d(gmsh, domain);
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
