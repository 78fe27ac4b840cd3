#include "fsi/fluid/remesh.hpp"

#include <fmt/format.h>
#include <gmsh.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>

#include "fsi/fluid/field_transfer.hpp"

namespace fsi::fluid {
namespace {

struct BoundaryEdge {
  int a, b;      // old vertices, the domain on the left (the triangle's counter-clockwise order)
  int mid = -1;  // old midpoint node (6-node meshes)
};

// The edges used by one triangle only, oriented as in that triangle.
std::vector<BoundaryEdge> boundary_edges(const FluidMesh& mesh) {
  std::map<std::pair<int, int>, std::pair<int, BoundaryEdge>> edges;  // (min, max) -> (uses, oriented edge)
  for (int e = 0; e < mesh.triangle_count(); ++e)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles(e, k), b = mesh.triangles(e, (k + 1) % 3);
      auto& entry = edges[{std::min(a, b), std::max(a, b)}];
      ++entry.first;
      entry.second = {a, b, mesh.quadratic() ? mesh.edge_nodes(e, k) : -1};
    }
  std::vector<BoundaryEdge> out;
  for (const auto& [key, entry] : edges)
    if (entry.first == 1) out.push_back(entry.second);
  return out;
}

double signed_area(const Eigen::MatrixX2d& x, int a, int b, int c) {
  const Eigen::Vector2d u = x.row(b) - x.row(a), v = x.row(c) - x.row(a);
  return 0.5 * (u.x() * v.y() - u.y() * v.x());
}

// gmsh is initialised for one remesh and finalised after it (also on errors).
struct GmshSession {
  GmshSession() {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 1);
    gmsh::option::setNumber("General.NumThreads", 1);
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

}  // namespace

Eigen::VectorXd reference_sizes(const FluidMesh& mesh) {
  const int nv = mesh.vertices();
  Eigen::VectorXd size = Eigen::VectorXd::Zero(nv), count = Eigen::VectorXd::Zero(nv);
  for (int e = 0; e < mesh.triangle_count(); ++e) {
    const double area =
        std::abs(signed_area(mesh.nodes, mesh.triangles(e, 0), mesh.triangles(e, 1), mesh.triangles(e, 2)));
    const double h = std::sqrt(4 * area / std::sqrt(3.0));
    for (int k = 0; k < 3; ++k) size(mesh.triangles(e, k)) += h, count(mesh.triangles(e, k)) += 1;
  }
  for (int v = 0; v < nv; ++v) size(v) /= std::max(count(v), 1.0);
  return size;
}

RemeshResult remesh(const FluidMesh& mesh, const Eigen::MatrixX2d& positions, const Eigen::VectorXd& vertex_size) {
  const auto t0 = std::chrono::steady_clock::now();
  if (positions.rows() != mesh.node_count()) throw std::invalid_argument("remesh: positions has the wrong size");
  const int nv_old = mesh.vertices();
  const auto edges = boundary_edges(mesh);

  // Kept vertices: the boundary's, in their old order.
  std::vector<int> kept;
  for (const auto& e : edges) kept.push_back(e.a), kept.push_back(e.b);
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  std::vector<int> new_vertex(static_cast<std::size_t>(nv_old), -1);
  for (std::size_t i = 0; i < kept.size(); ++i) new_vertex[static_cast<std::size_t>(kept[i])] = static_cast<int>(i);

  const Eigen::VectorXd size = vertex_size.size() == 0 ? reference_sizes(mesh) : vertex_size;
  if (size.size() != nv_old) throw std::invalid_argument("remesh: vertex_size has the wrong size");

  // Boundary loops: each kept vertex starts exactly one boundary edge.
  std::vector<int> out_edge(static_cast<std::size_t>(nv_old), -1);
  for (std::size_t j = 0; j < edges.size(); ++j) {
    int& slot = out_edge[static_cast<std::size_t>(edges[j].a)];
    if (slot >= 0)
      throw std::runtime_error(
          fmt::format("remesh: the boundary touches itself at node {} (two boundary edges start "
                      "there)",
                      edges[j].a));
    slot = static_cast<int>(j);
  }
  std::vector<std::vector<int>> loops;  // boundary edge indices
  std::vector<char> used(edges.size(), 0);
  for (std::size_t j0 = 0; j0 < edges.size(); ++j0) {
    if (used[j0]) continue;
    std::vector<int> loop;
    for (int j = static_cast<int>(j0); !used[static_cast<std::size_t>(j)];) {
      used[static_cast<std::size_t>(j)] = 1;
      loop.push_back(j);
      j = out_edge[static_cast<std::size_t>(edges[static_cast<std::size_t>(j)].b)];
      if (j < 0) throw std::runtime_error("remesh: the boundary is not closed");
    }
    loops.push_back(std::move(loop));
  }
  // The outer loop: the largest (counter-clockwise) area.
  std::size_t outer = 0;
  double best = -1e300;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    double area = 0;
    for (int j : loops[l]) {
      const auto& e = edges[static_cast<std::size_t>(j)];
      area += 0.5 * (positions(e.a, 0) * positions(e.b, 1) - positions(e.b, 0) * positions(e.a, 1));
    }
    if (area > best) best = area, outer = l;
  }

  RemeshResult result;
  std::vector<Eigen::RowVector2d> vertex_xy;
  std::vector<std::array<int, 3>> tris;
  {
    GmshSession session;
    gmsh::model::add("remesh");
    for (std::size_t i = 0; i < kept.size(); ++i)
      gmsh::model::geo::addPoint(positions(kept[i], 0), positions(kept[i], 1), 0.0, size(kept[i]),
                                 static_cast<int>(i) + 1);
    for (std::size_t j = 0; j < edges.size(); ++j)
      gmsh::model::geo::addLine(new_vertex[static_cast<std::size_t>(edges[j].a)] + 1,
                                new_vertex[static_cast<std::size_t>(edges[j].b)] + 1, static_cast<int>(j) + 1);
    std::vector<int> wires;
    for (std::size_t l = 0; l < loops.size(); ++l) {
      std::vector<int> curves;
      for (int j : loops[l]) curves.push_back(j + 1);
      const int w = gmsh::model::geo::addCurveLoop(curves);
      if (l == outer)
        wires.insert(wires.begin(), w);
      else
        wires.push_back(w);
    }
    gmsh::model::geo::addPlaneSurface(wires, 1);
    gmsh::model::geo::synchronize();
    for (std::size_t j = 0; j < edges.size(); ++j) gmsh::model::mesh::setTransfiniteCurve(static_cast<int>(j) + 1, 2);

    // The background size field: the old sizes on the old triangles at their current positions.
    const int view = gmsh::view::add("sizes");
    std::vector<double> data;
    data.reserve(static_cast<std::size_t>(mesh.triangle_count()) * 12);
    for (int e = 0; e < mesh.triangle_count(); ++e) {
      for (int c = 0; c < 2; ++c)
        for (int k = 0; k < 3; ++k) data.push_back(positions(mesh.triangles(e, k), c));
      for (int k = 0; k < 3; ++k) data.push_back(0.0);
      for (int k = 0; k < 3; ++k) data.push_back(size(mesh.triangles(e, k)));
    }
    gmsh::view::addListData(view, "ST", mesh.triangle_count(), data);
    const int field = gmsh::model::mesh::field::add("PostView");
    gmsh::model::mesh::field::setNumber(field, "ViewIndex", gmsh::view::getIndex(view));
    gmsh::model::mesh::field::setAsBackgroundMesh(field);
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
    gmsh::option::setNumber("Mesh.Algorithm", 6);  // frontal-Delaunay
    gmsh::model::mesh::generate(2);

    // Nodes: the points are the kept vertices; the rest are new interior vertices.
    std::map<std::size_t, int> index;  // gmsh node tag -> new vertex
    std::vector<std::size_t> tags;
    std::vector<double> coord, param;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      gmsh::model::mesh::getNodes(tags, coord, param, 0, static_cast<int>(i) + 1, false, false);
      if (tags.size() != 1) throw std::runtime_error("remesh: gmsh lost a boundary point");
      index[tags[0]] = static_cast<int>(i);
    }
    vertex_xy.resize(kept.size());
    for (std::size_t i = 0; i < kept.size(); ++i) vertex_xy[i] = positions.row(kept[i]);
    gmsh::model::mesh::getNodes(tags, coord, param, 2, 1, false, false);
    for (std::size_t k = 0; k < tags.size(); ++k) {
      index[tags[k]] = static_cast<int>(vertex_xy.size());
      vertex_xy.emplace_back(coord[3 * k], coord[3 * k + 1]);
    }
    gmsh::model::mesh::getNodes(tags, coord, param, 1, -1, false, false);
    if (!tags.empty()) throw std::runtime_error("remesh: gmsh split a boundary edge");
    std::vector<std::size_t> element_tags, element_nodes;
    gmsh::model::mesh::getElementsByType(2, element_tags, element_nodes, 1);
    for (std::size_t t = 0; t < element_tags.size(); ++t) {
      std::array<int, 3> tri{};
      for (int k = 0; k < 3; ++k) {
        const auto it = index.find(element_nodes[3 * t + static_cast<std::size_t>(k)]);
        if (it == index.end()) throw std::runtime_error("remesh: a gmsh triangle has an unknown node");
        tri[static_cast<std::size_t>(k)] = it->second;
      }
      tris.push_back(tri);
    }
  }

  // The new mesh (linear), counter-clockwise.
  FluidMesh& out = result.mesh;
  const int nv = static_cast<int>(vertex_xy.size());
  out.nodes.resize(nv, 2);
  for (int i = 0; i < nv; ++i) out.nodes.row(i) = vertex_xy[static_cast<std::size_t>(i)];
  out.triangles.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t t = 0; t < tris.size(); ++t) {
    auto tri = tris[t];
    const double a = signed_area(out.nodes, tri[0], tri[1], tri[2]);
    if (a == 0) throw std::runtime_error("remesh: gmsh made a degenerate triangle");
    if (a < 0) std::swap(tri[1], tri[2]);
    out.triangles.row(static_cast<Eigen::Index>(t)) << tri[0], tri[1], tri[2];
  }
  for (const auto& [name, seg] : mesh.boundaries) {
    IndexMatrix2 s(seg.rows(), 2);
    for (Eigen::Index r = 0; r < seg.rows(); ++r)
      for (int c = 0; c < 2; ++c) s(r, c) = new_vertex[static_cast<std::size_t>(seg(r, c))];
    out.boundaries[name] = std::move(s);
  }
  result.old_node.assign(static_cast<std::size_t>(nv), -1);
  for (std::size_t i = 0; i < kept.size(); ++i) result.old_node[i] = kept[i];
  {
    const MeshLocator locator(mesh, positions);
    result.vertex_size = interpolate_field(locator, mesh, Eigen::MatrixXd(size), out.nodes).col(0);
    for (std::size_t i = 0; i < kept.size(); ++i) result.vertex_size(static_cast<Eigen::Index>(i)) = size(kept[i]);
  }

  if (mesh.quadratic()) {
    // Midpoints: the kept boundary ones (old order) first, then the interior edge centres.
    std::map<std::pair<int, int>, int> old_mid;  // new vertex pair -> old midpoint
    std::vector<int> kept_mid;
    for (const auto& e : edges) {
      const int a = new_vertex[static_cast<std::size_t>(e.a)], b = new_vertex[static_cast<std::size_t>(e.b)];
      old_mid[{std::min(a, b), std::max(a, b)}] = e.mid;
      kept_mid.push_back(e.mid);
    }
    std::sort(kept_mid.begin(), kept_mid.end());
    std::map<int, int> mid_index;  // old midpoint -> new node
    for (std::size_t i = 0; i < kept_mid.size(); ++i) mid_index[kept_mid[i]] = nv + static_cast<int>(i);
    std::map<std::pair<int, int>, int> interior;
    std::vector<Eigen::RowVector2d> extra;
    out.edge_nodes.resize(out.triangle_count(), 3);
    for (int t = 0; t < out.triangle_count(); ++t)
      for (int k = 0; k < 3; ++k) {
        const int a = out.triangles(t, k), b = out.triangles(t, (k + 1) % 3);
        const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
        if (const auto it = old_mid.find(key); it != old_mid.end()) {
          out.edge_nodes(t, k) = mid_index.at(it->second);
          continue;
        }
        auto [it, inserted] = interior.emplace(key, nv + static_cast<int>(kept_mid.size() + extra.size()));
        if (inserted) extra.push_back(0.5 * (out.nodes.row(a) + out.nodes.row(b)));
        out.edge_nodes(t, k) = it->second;
      }
    Eigen::MatrixX2d all(nv + static_cast<Eigen::Index>(kept_mid.size() + extra.size()), 2);
    all.topRows(nv) = out.nodes;
    for (std::size_t i = 0; i < kept_mid.size(); ++i)
      all.row(nv + static_cast<Eigen::Index>(i)) = positions.row(kept_mid[i]);
    for (std::size_t i = 0; i < extra.size(); ++i)
      all.row(nv + static_cast<Eigen::Index>(kept_mid.size() + i)) = extra[i];
    out.nodes = std::move(all);
    out.vertex_count = nv;
    for (const auto& [name, mid] : mesh.boundary_midpoints) {
      Eigen::VectorXi m(mid.size());
      for (Eigen::Index r = 0; r < mid.size(); ++r) m(r) = mid_index.at(mid(r));
      out.boundary_midpoints[name] = std::move(m);
    }
    result.old_node.resize(static_cast<std::size_t>(out.node_count()), -1);
    for (std::size_t i = 0; i < kept_mid.size(); ++i) result.old_node[static_cast<std::size_t>(nv) + i] = kept_mid[i];
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace fsi::fluid
