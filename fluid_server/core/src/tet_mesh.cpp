#include "fsi/fluid/tet_mesh.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <map>
#include <stdexcept>

namespace fsi::fluid {
namespace {

double signed_volume(const Eigen::MatrixX3d& x, int a, int b, int c, int d) {
  Eigen::Matrix3d J;
  J.col(0) = (x.row(b) - x.row(a)).transpose();
  J.col(1) = (x.row(c) - x.row(a)).transpose();
  J.col(2) = (x.row(d) - x.row(a)).transpose();
  return J.determinant() / 6.0;
}

// Vertices 1 <-> 2 swapped: edges 01 <-> 20 (0 <-> 2), 12 stays, 30 stays, 32 <-> 31 (4 <-> 5).
void flip(Eigen::Ref<Eigen::Matrix<int, 1, 4>> v, int* mid) {
  std::swap(v(1), v(2));
  if (mid) {
    std::swap(mid[0], mid[2]);
    std::swap(mid[4], mid[5]);
  }
}

}  // namespace

const IndexMatrixT3& TetMesh::boundary(const std::string& name) const {
  const auto it = boundaries.find(name);
  if (it != boundaries.end()) return it->second;
  std::string known;
  for (const auto& [n, _] : boundaries) known += (known.empty() ? "" : ", ") + n;
  throw std::runtime_error(
      fmt::format("fluid mesh has no boundary group '{}' (groups: {})", name, known.empty() ? "none" : known));
}

std::vector<int> TetMesh::boundary_nodes(const std::vector<std::string>& names) const {
  std::vector<int> result;
  for (const auto& name : names) {
    const auto& f = boundary(name);
    result.insert(result.end(), f.data(), f.data() + f.size());
    if (const auto it = boundary_midpoints.find(name); it != boundary_midpoints.end())
      result.insert(result.end(), it->second.data(), it->second.data() + it->second.size());
  }
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

Eigen::Matrix<int, 10, 1> TetMesh::element_nodes10(int e) const {
  Eigen::Matrix<int, 10, 1> n;
  for (int k = 0; k < 4; ++k) n(k) = tets(e, k);
  for (int k = 0; k < 6; ++k) n(4 + k) = edge_nodes(e, k);
  return n;
}

TetMesh TetMesh::quadratic_from_linear() const {
  if (quadratic()) return *this;
  TetMesh out;
  out.tets = tets;
  out.boundaries = boundaries;
  out.vertex_count = node_count();
  out.edge_nodes.resize(cell_count(), 6);
  std::map<std::pair<int, int>, int> edge_index;
  std::vector<Eigen::RowVector3d> extra;
  auto midpoint = [&](int a, int b) {
    const auto key = std::make_pair(std::min(a, b), std::max(a, b));
    auto [it, inserted] = edge_index.emplace(key, node_count() + static_cast<int>(extra.size()));
    if (inserted) extra.push_back(0.5 * (nodes.row(a) + nodes.row(b)));
    return it->second;
  };
  for (int e = 0; e < cell_count(); ++e)
    for (int k = 0; k < 6; ++k) out.edge_nodes(e, k) = midpoint(tets(e, kTetEdges[k][0]), tets(e, kTetEdges[k][1]));
  for (const auto& [name, faces] : boundaries) {
    IndexMatrixT3 mid(faces.rows(), 3);
    for (Eigen::Index s = 0; s < faces.rows(); ++s)
      for (int k = 0; k < 3; ++k) {
        const int a = faces(s, k), b = faces(s, (k + 1) % 3);
        const auto it = edge_index.find({std::min(a, b), std::max(a, b)});
        if (it == edge_index.end())
          throw std::runtime_error(
              fmt::format("boundary group '{}': face edge ({}, {}) is not a tetrahedron edge", name, a, b));
        mid(s, k) = it->second;
      }
    out.boundary_midpoints[name] = std::move(mid);
  }
  out.nodes.resize(node_count() + static_cast<Eigen::Index>(extra.size()), 3);
  out.nodes.topRows(node_count()) = nodes;
  for (std::size_t i = 0; i < extra.size(); ++i) out.nodes.row(node_count() + static_cast<Eigen::Index>(i)) = extra[i];
  return out;
}

TetMesh TetMesh::from_gmsh(const GmshMesh& mesh, const std::vector<std::string>& domain_groups) {
  std::vector<const GmshGroup*> cells;
  int cell_type = 0;
  for (const auto& g : mesh.groups) {
    if (g.dimension != 3) continue;
    if (!domain_groups.empty() && std::find(domain_groups.begin(), domain_groups.end(), g.name) == domain_groups.end())
      continue;
    if (g.element_type != 4 && g.element_type != 11)
      throw std::runtime_error(
          fmt::format("{}: group '{}' has gmsh element type {}; the 3D fluid takes 4-node or "
                      "10-node tetrahedra",
                      mesh.source.string(), g.name, g.element_type));
    if (cell_type != 0 && g.element_type != cell_type)
      throw std::runtime_error(
          fmt::format("{}: the fluid groups mix 4-node and 10-node tetrahedra", mesh.source.string()));
    cell_type = g.element_type;
    cells.push_back(&g);
  }
  if (cells.empty())
    throw std::runtime_error(fmt::format(
        "{}: no tetrahedra for a 3D fluid (a 2D mesh? a 3D .geo needs a physical volume)", mesh.source.string()));
  const bool quad = cell_type == 11;
  std::vector<int> new_index(static_cast<std::size_t>(mesh.nodes.rows()), -1);
  int count = 0;
  Eigen::Index ntet = 0;
  for (const auto* g : cells) ntet += g->elements.rows();
  TetMesh out;
  out.tets.resize(ntet, 4);
  if (quad) out.edge_nodes.resize(ntet, 6);
  for (int pass = 0; pass < (quad ? 2 : 1); ++pass) {
    Eigen::Index t = 0;
    for (const auto* g : cells)
      for (Eigen::Index e = 0; e < g->elements.rows(); ++e, ++t)
        for (int k = 0; k < (pass == 0 ? 4 : 6); ++k) {
          int& idx = new_index[static_cast<std::size_t>(g->elements(e, 4 * pass + k))];
          if (idx < 0) idx = count++;
          (pass == 0 ? out.tets(t, k) : out.edge_nodes(t, k)) = idx;
        }
    if (pass == 0) out.vertex_count = count;
  }
  if (!quad) out.vertex_count = -1;
  out.nodes.resize(count, 3);
  for (Eigen::Index i = 0; i < mesh.nodes.rows(); ++i)
    if (const int k = new_index[static_cast<std::size_t>(i)]; k >= 0)
      out.nodes.row(k) << mesh.nodes(i, 0), mesh.nodes(i, 1), mesh.z.size() ? mesh.z(i) : 0.0;
  for (Eigen::Index e = 0; e < ntet; ++e) {
    const double v = signed_volume(out.nodes, out.tets(e, 0), out.tets(e, 1), out.tets(e, 2), out.tets(e, 3));
    if (v == 0) throw std::runtime_error(fmt::format("{}: degenerate tetrahedron {}", mesh.source.string(), e));
    if (v < 0) flip(out.tets.row(e), quad ? out.edge_nodes.row(e).data() : nullptr);
  }
  for (const auto& g : mesh.groups) {
    if (g.dimension != 2) continue;
    const int expected = quad ? 9 : 2;
    if (g.element_type != expected)
      throw std::runtime_error(fmt::format("{}: boundary group '{}' has gmsh element type {}; expected {} triangles",
                                           mesh.source.string(), g.name, g.element_type, quad ? "6-node" : "3-node"));
    IndexMatrixT3 faces(g.elements.rows(), 3), mid(quad ? g.elements.rows() : 0, 3);
    for (Eigen::Index e = 0; e < g.elements.rows(); ++e)
      for (int k = 0; k < (quad ? 6 : 3); ++k) {
        const int idx = new_index[static_cast<std::size_t>(g.elements(e, k))];
        if (idx < 0)
          throw std::runtime_error(fmt::format("{}: boundary group '{}' has a node outside the fluid tetrahedra",
                                               mesh.source.string(), g.name));
        (k < 3 ? faces(e, k) : mid(e, k - 3)) = idx;
      }
    out.boundaries[g.name] = std::move(faces);
    if (quad) out.boundary_midpoints[g.name] = std::move(mid);
  }
  return out;
}

TetMesh TetMesh::box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int nx, int ny, int nz) {
  TetMesh out;
  auto id = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  out.nodes.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        out.nodes.row(id(i, j, k)) << lo.x() + (hi.x() - lo.x()) * i / nx, lo.y() + (hi.y() - lo.y()) * j / ny,
            lo.z() + (hi.z() - lo.z()) * k / nz;
  // Kuhn's 6 tetrahedra along the cell diagonal 0 -> 7 (corners c = i + 2 j + 4 k).
  static const int kPaths[6][3] = {{1, 3, 7}, {1, 5, 7}, {2, 3, 7}, {2, 6, 7}, {4, 5, 7}, {4, 6, 7}};
  out.tets.resize(6 * nx * ny * nz, 4);
  int t = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        auto corner = [&](int c) { return id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)); };
        for (const auto& p : kPaths) {
          out.tets.row(t) << corner(0), corner(p[0]), corner(p[1]), corner(p[2]);
          if (signed_volume(out.nodes, out.tets(t, 0), out.tets(t, 1), out.tets(t, 2), out.tets(t, 3)) < 0)
            flip(out.tets.row(t), nullptr);
          ++t;
        }
      }
  // Boundary faces: the tetrahedron faces with all three vertices on a side.
  const std::array<std::pair<std::string, std::pair<int, double>>, 6> sides = {{{"left", {0, lo.x()}},
                                                                                {"right", {0, hi.x()}},
                                                                                {"bottom", {1, lo.y()}},
                                                                                {"top", {1, hi.y()}},
                                                                                {"back", {2, lo.z()}},
                                                                                {"front", {2, hi.z()}}}};
  static const int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (const auto& [name, side] : sides) {
    std::vector<std::array<int, 3>> faces;
    for (int e = 0; e < out.cell_count(); ++e)
      for (const auto& f : kFaces) {
        bool on = true;
        for (int v : f) on = on && std::abs(out.nodes(out.tets(e, v), side.first) - side.second) < 1e-12;
        if (on) faces.push_back({out.tets(e, f[0]), out.tets(e, f[1]), out.tets(e, f[2])});
      }
    IndexMatrixT3 m(static_cast<Eigen::Index>(faces.size()), 3);
    for (std::size_t s = 0; s < faces.size(); ++s)
      m.row(static_cast<Eigen::Index>(s)) << faces[s][0], faces[s][1], faces[s][2];
    out.boundaries[name] = std::move(m);
  }
  return out;
}

}  // namespace fsi::fluid
