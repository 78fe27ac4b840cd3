// The interface in three dimensions: face geometry (areas, interface mass), the nearest
// projection onto triangles and quadrilaterals (linear and quadratic) with its transpose for
// forces, the RBF mapping in 3D (affine fields, rotations, resultant and work to round-off),
// convergence on a curved surface, and the refusal of meshes of different dimensions.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <iostream>
#include <map>
#include <random>

#include "fsi/common/interface_geometry.hpp"
#include "fsi/coupling/interface_map.hpp"

namespace {

using fsi::InterfaceMeshData;

// A plate of a x b centred at c, tilted: its edges along two orthonormal directions that
// are not coordinate axes (so every component of every mapping is exercised).
struct Frame {
  Eigen::Vector3d c{0.3, -0.2, 0.7};
  Eigen::Matrix3d R = (Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  Eigen::Vector3d e1() const { return R.col(0); }
  Eigen::Vector3d e2() const { return R.col(1); }
};

InterfaceMeshData plate(int n1, int n2, bool triangles) {
  const Frame f;
  return fsi::rectangle_surface(f.c, f.e1(), f.e2(), 2.0, 1.0, n1, n2, triangles);
}

// The same mesh with quadratic faces: mid-edge nodes (shared between neighbours) and, for
// quadrilaterals, a centre node (quad9); triangles become tri6, in gmsh's node order.
InterfaceMeshData quadratic(const InterfaceMeshData& linear) {
  InterfaceMeshData q = linear;
  std::vector<Eigen::Vector3d> points;
  for (Eigen::Index i = 0; i < linear.coordinates.rows(); ++i) points.emplace_back(linear.coordinates.row(i));
  std::map<std::pair<int, int>, int> mid;
  auto midpoint = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    const auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    points.push_back(0.5 * (points[a] + points[b]));
    return mid[key] = static_cast<int>(points.size()) - 1;
  };
  q.faces.clear();
  for (const auto& face : linear.faces) {
    const auto& n = face.nodes;
    fsi::InterfaceFace out{n};
    for (std::size_t k = 0; k < n.size(); ++k) out.nodes.push_back(midpoint(n[k], n[(k + 1) % n.size()]));
    if (n.size() == 4) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (int v : n) centre += points[v] / 4;
      points.push_back(centre);
      out.nodes.push_back(static_cast<int>(points.size()) - 1);
    }
    q.faces.push_back(out);
  }
  q.coordinates.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) q.coordinates.row(static_cast<Eigen::Index>(i)) = points[i];
  q.node_ids.clear();
  for (std::size_t i = 0; i < points.size(); ++i) q.node_ids.push_back(static_cast<std::int64_t>(i));
  q.lumped_measure = fsi::lumped_interface_measure(q);
  return q;
}

// u(x) = A x + b at every node, interleaved.
Eigen::VectorXd affine(const InterfaceMeshData& mesh, const Eigen::Matrix3d& A, const Eigen::Vector3d& b) {
  Eigen::VectorXd u(3 * mesh.coordinates.rows());
  for (Eigen::Index i = 0; i < mesh.coordinates.rows(); ++i)
    u.segment<3>(3 * i) = A * mesh.coordinates.row(i).transpose() + b;
  return u;
}

const Eigen::Matrix3d kA = (Eigen::Matrix3d() << 0.3, -1.2, 0.5, 2.0, 0.1, -0.7, -0.4, 0.9, 1.5).finished();
const Eigen::Vector3d kB(0.25, -1.5, 3.0);

TEST(FaceGeometry, AreasAndInterfaceMassOfEveryFaceKind) {
  for (bool tri : {false, true})
    for (bool quad_order : {false, true}) {
      const auto lin = plate(3, 2, tri);
      const auto mesh = quad_order ? quadratic(lin) : lin;
      double area = 0;
      for (const auto& f : mesh.faces) area += fsi::face_area(mesh.coordinates, f);
      EXPECT_NEAR(area, 2.0, 1e-13) << "triangles " << tri << " quadratic " << quad_order;
      const auto M = fsi::nodal_interface_mass(mesh, Eigen::VectorXd());
      EXPECT_NEAR(M.sum(), 2.0, 1e-13);  // 1^T M 1 = |Gamma|
      // x^T M x = int x^2: the first tangential coordinate s in [-1, 1], int s^2 = 2/3 * b.
      Eigen::VectorXd s(mesh.coordinates.rows());
      const Frame f;
      for (Eigen::Index i = 0; i < s.size(); ++i) s[i] = (mesh.coordinates.row(i).transpose() - f.c).dot(f.e1());
      EXPECT_NEAR(s.dot(M * s), 2.0 / 3.0, 1e-13);
      EXPECT_NEAR(mesh.lumped_measure.sum(), 2.0, 1e-13);
    }
}

TEST(FaceGeometry, ProjectionFindsTheClosestPointOnCurvedQuadraticFaces) {
  // One quad9 face bent into z = 0.2 (x^2 - y^2) at its mid-edge and centre nodes: a point
  // above it projects to where the distance is stationary (the offset along the normal).
  InterfaceMeshData q = quadratic(fsi::rectangle_surface(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                                                         Eigen::Vector3d::UnitY(), 2, 2, 1, 1, false));
  for (Eigen::Index i = 0; i < q.coordinates.rows(); ++i) {
    const double x = q.coordinates(i, 0), y = q.coordinates(i, 1);
    q.coordinates(i, 2) = 0.2 * (x * x - y * y);
  }
  const fsi::InterfaceFace& face = q.faces.front();
  const Eigen::Vector3d on = fsi::face_point(q.coordinates, face, 0.3, -0.4);
  // The face's normal at (0.3, -0.4) by central differences of the map.
  const double h = 1e-6;
  const Eigen::Vector3d t1 =
      (fsi::face_point(q.coordinates, face, 0.3 + h, -0.4) - fsi::face_point(q.coordinates, face, 0.3 - h, -0.4)) /
      (2 * h);
  const Eigen::Vector3d t2 =
      (fsi::face_point(q.coordinates, face, 0.3, -0.4 + h) - fsi::face_point(q.coordinates, face, 0.3, -0.4 - h)) /
      (2 * h);
  const Eigen::Vector3d n = t1.cross(t2).normalized();
  const auto p = fsi::project_on_face(q.coordinates, face, on + 0.05 * n);
  EXPECT_NEAR(p.xi, 0.3, 1e-7);
  EXPECT_NEAR(p.eta, -0.4, 1e-7);
  EXPECT_NEAR(p.distance, 0.05, 1e-8);
}

struct Pairing {
  bool solid_triangles, solid_quadratic, fluid_triangles;
};

class NearestProjection3d : public ::testing::TestWithParam<Pairing> {};

TEST_P(NearestProjection3d, AffineFieldsExactForcesAndWorkConserved) {
  const auto p = GetParam();
  const auto lin = plate(3, 2, p.solid_triangles);
  const auto solid = p.solid_quadratic ? quadratic(lin) : lin;
  const auto fluid = plate(7, 5, p.fluid_triangles);  // nodes nowhere near the solid's
  const fsi::coupling::InterfaceMap map(solid, fluid);
  EXPECT_FALSE(map.conforming());
  EXPECT_LT(map.max_gap(), 1e-12);
  // Consistent: an affine field (rigid motions among them) is carried exactly.
  const Eigen::VectorXd uf = map.to_fluid(affine(solid, kA, kB));
  EXPECT_LT((uf - affine(fluid, kA, kB)).lpNorm<Eigen::Infinity>(), 1e-12);
  // Conservative: H^T keeps the resultant force and the work f_f . H v_s.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd ff(3 * fluid.coordinates.rows()), vs(3 * solid.coordinates.rows());
  for (auto& x : ff) x = U(rng);
  for (auto& x : vs) x = U(rng);
  const Eigen::VectorXd fs = map.to_solid(ff);
  for (int c = 0; c < 3; ++c) {
    double a = 0, b = 0;
    for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i) a += ff[3 * i + c];
    for (Eigen::Index i = 0; i < solid.coordinates.rows(); ++i) b += fs[3 * i + c];
    EXPECT_NEAR(a, b, 1e-12) << "component " << c;
  }
  EXPECT_NEAR(ff.dot(map.to_fluid(vs)), fs.dot(vs), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Faces, NearestProjection3d,
                         ::testing::Values(Pairing{false, false, true}, Pairing{true, false, false},
                                           Pairing{false, true, true}, Pairing{true, true, false}));

TEST(NearestProjection3d, OffsetNodesTakeTheirClosestPointsAndTheGapIsReported) {
  const auto solid = plate(2, 2, false);
  auto fluid = plate(5, 3, true);
  const Frame f;
  const Eigen::Vector3d normal = f.e1().cross(f.e2());
  for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i) fluid.coordinates.row(i) += 0.01 * normal.transpose();
  const fsi::coupling::InterfaceMap map(solid, fluid);
  EXPECT_NEAR(map.max_gap(), 0.01, 1e-12);
  // The in-plane part of an affine field is still exact at the closest points.
  const Eigen::VectorXd uf = map.to_fluid(affine(solid, kA, kB));
  const Eigen::VectorXd expected = affine(fluid, kA, kB);
  for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i)
    EXPECT_LT((uf.segment<3>(3 * i) - (expected.segment<3>(3 * i) - 0.01 * kA * normal)).norm(), 1e-12);
}

TEST(NearestProjection3d, MatchingMeshesAreAPermutation) {
  const auto solid = plate(3, 3, true);
  auto fluid = solid;
  // The fluid lists the same nodes in reverse.
  const Eigen::Index n = solid.coordinates.rows();
  for (Eigen::Index i = 0; i < n; ++i) fluid.coordinates.row(i) = solid.coordinates.row(n - 1 - i);
  for (auto& face : fluid.faces)
    for (int& v : face.nodes) v = static_cast<int>(n - 1 - v);
  const fsi::coupling::InterfaceMap map(solid, fluid);
  EXPECT_TRUE(map.conforming());
  EXPECT_LT(map.permutation_error(), 1e-12);
}

class Rbf3d : public ::testing::TestWithParam<fsi::coupling::MappingKind> {};

INSTANTIATE_TEST_SUITE_P(Kernels, Rbf3d,
                         ::testing::Values(fsi::coupling::MappingKind::RbfThinPlateSpline,
                                           fsi::coupling::MappingKind::RbfWendlandC2));

// Half a cylinder of radius R (theta in [0, pi], z in [0, H]): its nodes on the cylinder, its
// faces the chords between them (linear) or, quadratic, curved through mid-edge nodes that are
// on the cylinder too.
InterfaceMeshData half_cylinder(int n_theta, int n_z, bool triangles, bool curved) {
  const double R = 0.5, H = 1.0;
  auto m = fsi::rectangle_surface(Eigen::Vector3d(0.5, 0.5, 0), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 1.0,
                                  1.0, n_theta, n_z, triangles);
  if (curved) m = quadratic(m);
  for (Eigen::Index i = 0; i < m.coordinates.rows(); ++i) {
    const double theta = M_PI * m.coordinates(i, 0), z = H * m.coordinates(i, 1);
    m.coordinates.row(i) << R * std::cos(theta), R * std::sin(theta), z;
  }
  m.lumped_measure = fsi::lumped_interface_measure(m);
  return m;
}

// The nodes of a triangle mesh of n_theta x n_z cells on the surface of `solid` (a
// half_cylinder): each node at the point of the solid's face above its (theta, z) parameters,
// so on the solid's faceted (or curved quadratic) surface, not on the true cylinder, and
// nowhere near the solid's nodes.
InterfaceMeshData on_solid_surface(const InterfaceMeshData& solid, int n_solid_theta, int n_solid_z, int n_theta,
                                   int n_z) {
  auto fluid = half_cylinder(n_theta, n_z, true, false);
  for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i) {
    const Eigen::Vector3d x = fluid.coordinates.row(i);
    const double s = std::atan2(x.y(), x.x()) / M_PI * n_solid_theta, t = x.z() * n_solid_z;  // cell units
    const int a = std::clamp(static_cast<int>(s), 0, n_solid_theta - 1),
              b = std::clamp(static_cast<int>(t), 0, n_solid_z - 1);
    // The solid's face (a, b): the one whose corners have these cell coordinates.
    for (const auto& face : solid.faces) {
      Eigen::Vector2d lo(1e9, 1e9);
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3d v = solid.coordinates.row(face.nodes[k]);
        lo = lo.cwiseMin(Eigen::Vector2d(std::atan2(v.y(), v.x()) / M_PI * n_solid_theta, v.z() * n_solid_z));
      }
      if (std::abs(lo.x() - a) > 1e-9 || std::abs(lo.y() - b) > 1e-9) continue;
      fluid.coordinates.row(i) = fsi::face_point(solid.coordinates, face, 2 * (s - a) - 1, 2 * (t - b) - 1).transpose();
      break;
    }
  }
  fluid.lumped_measure = fsi::lumped_interface_measure(fluid);
  return fluid;
}

// The components of the forces summed over each side's nodes (the resultant).
Eigen::Vector3d resultant(const Eigen::VectorXd& f) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < f.size() / 3; ++i) sum += f.segment<3>(3 * i);
  return sum;
}

// Conservation by the transpose, for forces of size 1 at every fluid node: the resultant and
// the work f_f . H v_s = (H^T f_f) . v_s of the two sides agree to 1e-12.
void expect_conservative(const fsi::coupling::InterfaceMap& map, Eigen::Index nf, Eigen::Index ns,
                         const std::string& what) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd ff(3 * nf), vs(3 * ns);
  for (auto& x : ff) x = U(rng);
  for (auto& x : vs) x = U(rng);
  const Eigen::VectorXd fs = map.to_solid(ff);
  EXPECT_LT((resultant(ff) - resultant(fs)).lpNorm<Eigen::Infinity>(), 1e-12) << what;
  EXPECT_LT(std::abs(ff.dot(map.to_fluid(vs)) - fs.dot(vs)), 1e-12) << what;
}

// RBF between non-matching 3D interfaces (solid quadrilaterals, fluid triangles of another
// size): a tilted plate, a saddle, half a cylinder (the fluid's nodes on the true cylinder, off
// the solid's flat faces) and a finer half cylinder (a few hundred solid nodes, where the
// system's condition number on the null space of the linear terms is up to 8e5). Affine fields and the displacements of
// rigid rotations (u = (R - I)(x - x_0) + t, a rotation of 63 degrees) are mapped exactly to round-off (1e-12 on fields
// of size 1-5), the resultant and the work are conserved to 1e-12 (measured: 3e-15 to 1.3e-14).
TEST_P(Rbf3d, AffineFieldsRotationsForcesAndWorkToRoundOffOnNonMatchingMeshes) {
  auto saddle = [](int n1, int n2, bool triangles) {
    auto m = fsi::rectangle_surface(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 1.0,
                                    1.0, n1, n2, triangles);
    for (Eigen::Index i = 0; i < m.coordinates.rows(); ++i) {
      const double x = m.coordinates(i, 0), y = m.coordinates(i, 1);
      m.coordinates(i, 2) = 0.3 * (x * x - y * y);
    }
    return m;
  };
  struct Case {
    const char* name;
    InterfaceMeshData solid, fluid;
  };
  const std::vector<Case> cases = {
      {"plate", plate(5, 3, false), plate(11, 7, true)},
      {"saddle", saddle(6, 6, false), saddle(13, 9, true)},
      {"half cylinder", half_cylinder(8, 4, false, false), half_cylinder(19, 9, true, false)},
      {"half cylinder, fine", half_cylinder(24, 12, false, false), half_cylinder(37, 17, true, false)},
  };
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(-0.3, 0.8, 0.5).normalized()).toRotationMatrix();
  const Eigen::Matrix3d A = rotation - Eigen::Matrix3d::Identity();
  const Eigen::Vector3d x0(0.2, -0.1, 0.4);
  fsi::coupling::MappingSettings settings;
  settings.kind = GetParam();
  for (const auto& c : cases) {
    const fsi::coupling::InterfaceMap map(c.solid, c.fluid, settings);
    const double affine_error =
        (map.to_fluid(affine(c.solid, kA, kB)) - affine(c.fluid, kA, kB)).lpNorm<Eigen::Infinity>();
    const double rotation_error =
        (map.to_fluid(affine(c.solid, A, kB - A * x0)) - affine(c.fluid, A, kB - A * x0)).lpNorm<Eigen::Infinity>();
    std::cout << to_string(settings.kind) << ", " << c.name << ": " << c.solid.coordinates.rows() << " -> "
              << c.fluid.coordinates.rows() << " nodes, condition " << map.condition_estimate() << ", affine "
              << affine_error << ", rotation " << rotation_error << "\n";
    EXPECT_LT(affine_error, 1e-12) << c.name;
    EXPECT_LT(rotation_error, 1e-12) << c.name;
    expect_conservative(map, c.fluid.coordinates.rows(), c.solid.coordinates.rows(), c.name);
  }
}

// The nearest projection between non-matching meshes of one curved surface: the fluid's
// triangles have their nodes on the solid's half cylinder (flat quad4 facets, or curved quad9
// faces) at other places than the solid's nodes. Affine fields are exact at every fluid node
// to 1e-12, the resultant and the work are conserved to 1e-12.
TEST(NearestProjection3d, AffineFieldsExactOnACurvedSurfaceOfTheSolid) {
  for (bool curved : {false, true}) {
    const auto solid = half_cylinder(8, 4, false, curved);
    const auto fluid = on_solid_surface(solid, 8, 4, 19, 11);
    const fsi::coupling::InterfaceMap map(solid, fluid);
    const std::string name = curved ? "quad9" : "quad4";
    EXPECT_LT(map.max_gap(), 1e-12) << name;
    const double error = (map.to_fluid(affine(solid, kA, kB)) - affine(fluid, kA, kB)).lpNorm<Eigen::Infinity>();
    std::cout << name << " half cylinder: affine error " << error << "\n";
    EXPECT_LT(error, 1e-12) << name;
    expect_conservative(map, fluid.coordinates.rows(), solid.coordinates.rows(), name);
  }
}

// A smooth field on the cylinder, mapped from a solid mesh refined three times (4 x 2 to
// 32 x 16 quadrilaterals) to a fine fluid one whose nodes lie on the true cylinder (off the
// solid's faceted faces); the largest error at the fluid's nodes and its order between
// successive meshes:
//   quad4 faces, projection:      9.3e-2, 2.5e-2, 6.4e-3, 1.7e-3   orders 1.9, 1.9, 2.0
//   quad9 faces, projection:      4.2e-3, 5.8e-4, 6.9e-5, 8.5e-6   orders 2.8, 3.1, 3.0
//   quad4 nodes, thin-plate RBF:  4.3e-2, 1.7e-2, 6.1e-3, 1.6e-3   orders 1.4, 1.5, 2.0
// (the thin-plate spline's interpolant of the solid's nodes on the true cylinder: it does not
// see the faces, and approaches second order as the nodes resolve the curvature).
TEST(Cylinder3d, SmoothFieldConvergesOnACurvedSurface) {
  auto field = [](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(std::sin(2 * x.z()) * x.x(), std::cos(x.y() + x.z()), x.x() * x.y());
  };
  auto error = [&](const InterfaceMeshData& solid, const InterfaceMeshData& fluid,
                   const fsi::coupling::MappingSettings& settings) {
    Eigen::VectorXd us(3 * solid.coordinates.rows());
    for (Eigen::Index i = 0; i < solid.coordinates.rows(); ++i)
      us.segment<3>(3 * i) = field(solid.coordinates.row(i).transpose());
    const Eigen::VectorXd uf = fsi::coupling::InterfaceMap(solid, fluid, settings).to_fluid(us);
    double e = 0;
    for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i)
      e = std::max(e, (uf.segment<3>(3 * i) - field(fluid.coordinates.row(i).transpose())).norm());
    return e;
  };
  const auto fluid = half_cylinder(60, 25, true, false);
  fsi::coupling::MappingSettings tps;
  tps.kind = fsi::coupling::MappingKind::RbfThinPlateSpline;
  struct Row {
    const char* name;
    bool curved;
    fsi::coupling::MappingSettings settings;
    double min_order;
  };
  for (const Row& row : {Row{"quad4 faces, projection", false, {}, 1.8}, Row{"quad9 faces, projection", true, {}, 2.7},
                         Row{"quad4 nodes, thin-plate RBF", false, tps, 1.3}}) {
    std::vector<double> e;
    for (int n : {4, 8, 16, 32}) e.push_back(error(half_cylinder(n, n / 2, false, row.curved), fluid, row.settings));
    std::cout << row.name << ": errors";
    for (double x : e) std::cout << " " << x;
    std::cout << ", orders";
    for (std::size_t k = 1; k < e.size(); ++k) std::cout << " " << std::log2(e[k - 1] / e[k]);
    std::cout << "\n";
    for (std::size_t k = 1; k < e.size(); ++k)
      EXPECT_GT(std::log2(e[k - 1] / e[k]), row.min_order) << row.name << " " << k;
  }
}

TEST(InterfaceMap3d, MeshesOfDifferentDimensionsAreRefusedNamingBoth) {
  const auto solid = plate(2, 2, false);
  InterfaceMeshData fluid;
  fluid.coordinates = Eigen::MatrixXd::Zero(2, 2);
  fluid.coordinates(1, 0) = 1;
  fluid.node_ids = {0, 1};
  fluid.segments = {{0, 1}};
  try {
    const fsi::coupling::InterfaceMap map(solid, fluid);
    FAIL() << "a 3D solid interface was mapped onto a 2D fluid interface";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("3"), std::string::npos) << what;
    EXPECT_NE(what.find("2"), std::string::npos) << what;
  }
}

// The check of the two face sets (check_interface_surfaces, run by the map's constructor):
// the message of a refused pair, or "" for an accepted one.
std::string refusal(const InterfaceMeshData& solid, const InterfaceMeshData& fluid) {
  try {
    const fsi::coupling::InterfaceMap map(solid, fluid);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// A cube's six faces, outwards, each divided into n x n quadrilaterals or triangles: a closed
// surface (the nodes of neighbouring sides merged).
InterfaceMeshData cube_surface(int n, bool triangles) {
  InterfaceMeshData out;
  out.dimension = 3;
  std::vector<Eigen::Vector3d> points;
  auto node = [&](const Eigen::Vector3d& x) {
    for (std::size_t i = 0; i < points.size(); ++i)
      if ((points[i] - x).norm() < 1e-12) return static_cast<int>(i);
    points.push_back(x);
    return static_cast<int>(points.size()) - 1;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-1.0, 1.0}) {
      Eigen::Vector3d n3 = Eigen::Vector3d::Zero();
      n3[axis] = side;
      const Eigen::Vector3d e1 = Eigen::Vector3d::Unit((axis + 1) % 3), e2 = n3.cross(e1);  // e1 x e2 = n
      const auto square = fsi::rectangle_surface(0.5 * n3, e1, e2, 1.0, 1.0, n, n, triangles);
      for (const auto& face : square.faces) {
        fsi::InterfaceFace f;
        for (int v : face.nodes) f.nodes.push_back(node(square.coordinates.row(v).transpose()));
        out.faces.push_back(f);
      }
    }
  out.coordinates.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) out.coordinates.row(static_cast<Eigen::Index>(i)) = points[i];
  for (std::size_t i = 0; i < points.size(); ++i) out.node_ids.push_back(static_cast<std::int64_t>(i));
  out.lumped_measure = fsi::lumped_interface_measure(out);
  return out;
}

// Interfaces that are surfaces ending on the same boundary are accepted: open plates of
// different faces and sizes (sdof_3d), an open half cylinder (quad9 faces against the fluid's
// triangles, whose boundary nodes are elsewhere on the curved ends), and closed cubes.
TEST(InterfaceSurfaces3d, MatchingOpenAndClosedSurfacesAreAccepted) {
  EXPECT_EQ(refusal(plate(2, 2, false), plate(3, 3, true)), "");
  EXPECT_EQ(refusal(quadratic(plate(3, 2, true)), plate(8, 5, false)), "");
  EXPECT_EQ(refusal(half_cylinder(8, 4, false, true), half_cylinder(19, 11, true, false)), "");
  EXPECT_EQ(refusal(cube_surface(2, false), cube_surface(5, true)), "");
}

// Broken face sets are refused, naming the side: a hole in either side (a face left out),
// a fluid surface larger than the solid's, a closed against an open surface, an edge with
// three faces, a face of reversed orientation.
TEST(InterfaceSurfaces3d, BrokenOrDifferentFaceSetsAreRefusedNamingTheSide) {
  auto without = [](InterfaceMeshData mesh, std::size_t face) {
    mesh.faces.erase(mesh.faces.begin() + static_cast<std::ptrdiff_t>(face));
    return mesh;
  };
  auto expect_refused = [](const std::string& message, const std::vector<std::string>& words) {
    EXPECT_NE(message, "");
    for (const auto& w : words) EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' in: " << message;
  };
  // The middle face of the solid's 3 x 3 plate missing: its four edges are a hole's rim.
  const auto solid = plate(3, 3, false), fluid = plate(7, 5, true);
  expect_refused(refusal(without(solid, 4), fluid),
                 {"the solid's interface has a boundary edge", "no boundary edge of the fluid's interface", "hole"});
  // A fluid triangle inside the plate missing.
  expect_refused(refusal(solid, without(fluid, 30)),
                 {"the fluid's interface has a boundary edge", "no boundary edge of the solid's interface"});
  // The fluid's plate larger than the solid's by more than half an element at one end.
  const Frame f;
  const auto larger =
      fsi::rectangle_surface(f.c + 0.25 * f.e1(), f.e1(), f.e2(), 2.5, 1.0, 9, 5, true);  // x from -1 to 1.5
  // The solid's end x = 1 lies inside the fluid's plate: the solid's boundary edge there is
  // refused first.
  expect_refused(refusal(solid, larger), {"the solid's interface has a boundary edge", "within 0.167"});
  // A closed cube against the same cube with one side open.
  expect_refused(refusal(without(cube_surface(2, false), 0), cube_surface(3, true)),
                 {"the solid's interface has a boundary edge", "the fluid's interface is closed"});
  // An extra solid face standing on an edge of the plate: three faces on one edge.
  auto fin = solid;
  {
    const auto& face = fin.faces[4];
    const Eigen::Vector3d a = fin.coordinates.row(face.nodes[0]), b = fin.coordinates.row(face.nodes[1]);
    const Eigen::Vector3d up = 0.3 * f.e1().cross(f.e2());
    fin.coordinates.conservativeResize(fin.coordinates.rows() + 1, 3);
    fin.coordinates.row(fin.coordinates.rows() - 1) = (0.5 * (a + b) + up).transpose();
    fin.faces.push_back({{face.nodes[1], face.nodes[0], static_cast<int>(fin.coordinates.rows() - 1)}});
    fin.node_ids.push_back(fin.coordinates.rows() - 1);
  }
  expect_refused(refusal(fin, fluid), {"the solid's interface is not a surface", "non-manifold"});
  // One fluid triangle turned over.
  auto flipped = fluid;
  std::swap(flipped.faces[12].nodes[1], flipped.faces[12].nodes[2]);
  expect_refused(refusal(solid, flipped), {"the fluid's interface faces are not consistently oriented"});
}

TEST(InterfaceMap3d, InterfaceMassSeenFromTheSolidKeepsTheArea) {
  const auto solid = quadratic(plate(2, 2, false));
  const auto fluid = plate(5, 4, true);
  const fsi::coupling::InterfaceMap map(solid, fluid);
  const auto Mf = fsi::nodal_interface_mass(fluid, Eigen::VectorXd());
  const auto Mg = map.mass_to_solid(Mf);
  EXPECT_NEAR(Mg.sum(), 2.0, 1e-12);  // a uniform velocity sees the whole area
  EXPECT_NEAR(fsi::coupling::interface_mass(solid, Eigen::VectorXd()).sum(), 3 * 2.0, 1e-12);  // 3 components
}

}  // namespace
