// The interface in three dimensions: face geometry (areas, interface mass), the nearest
// projection onto triangles and quadrilaterals (linear and quadratic) with its transpose for
// forces, the RBF mapping in 3D, and the refusal of meshes of different dimensions.
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

TEST_P(Rbf3d, RotationsAndAffineFieldsAreExactOnACurvedSurface) {
  // Nodes on the saddle z = 0.3 (x^2 - y^2): not in one plane, so all four linear terms stay.
  auto saddle = [](int n1, int n2) {
    auto m = fsi::rectangle_surface(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 1.0,
                                    1.0, n1, n2, false);
    for (Eigen::Index i = 0; i < m.coordinates.rows(); ++i) {
      const double x = m.coordinates(i, 0), y = m.coordinates(i, 1);
      m.coordinates(i, 2) = 0.3 * (x * x - y * y);
    }
    return m;
  };
  const auto solid = saddle(4, 4), fluid = saddle(7, 5);
  fsi::coupling::MappingSettings settings;
  settings.kind = GetParam();
  const fsi::coupling::InterfaceMap map(solid, fluid, settings);
  EXPECT_EQ(map.linear_terms(), 3);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(-0.3, 0.8, 0.5).normalized()).toRotationMatrix();
  // The displacement of a rigid rotation, u = (R - I) x + c.
  const Eigen::Matrix3d A = rotation - Eigen::Matrix3d::Identity();
  EXPECT_LT((map.to_fluid(affine(solid, A, kB)) - affine(fluid, A, kB)).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LT((map.to_fluid(affine(solid, kA, kB)) - affine(fluid, kA, kB)).lpNorm<Eigen::Infinity>(), 1e-9);
  // The transpose keeps the resultant.
  Eigen::VectorXd ff = Eigen::VectorXd::LinSpaced(3 * fluid.coordinates.rows(), -2, 5);
  const Eigen::VectorXd fs = map.to_solid(ff);
  for (int c = 0; c < 3; ++c) {
    double a = 0, b = 0;
    for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i) a += ff[3 * i + c];
    for (Eigen::Index i = 0; i < solid.coordinates.rows(); ++i) b += fs[3 * i + c];
    EXPECT_NEAR(a, b, 1e-9 * std::abs(a) + 1e-9);
  }
}

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

// A smooth field on the cylinder, mapped from a coarse solid mesh to a fine fluid one whose
// nodes lie on the true cylinder (off the solid's faceted faces): the nearest projection
// converges at second order with flat (linear) faces and at third order or better with
// curved quadratic ones; RBF keeps affine fields exact on the curved surface.
TEST(Cylinder3d, ProjectionConvergesOnACurvedSurface) {
  auto field = [](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(std::sin(2 * x.z()) * x.x(), std::cos(x.y() + x.z()), x.x() * x.y());
  };
  auto error = [&](const InterfaceMeshData& solid, const InterfaceMeshData& fluid) {
    Eigen::VectorXd us(3 * solid.coordinates.rows());
    for (Eigen::Index i = 0; i < solid.coordinates.rows(); ++i)
      us.segment<3>(3 * i) = field(solid.coordinates.row(i).transpose());
    const Eigen::VectorXd uf = fsi::coupling::InterfaceMap(solid, fluid).to_fluid(us);
    double e = 0;
    for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i)
      e = std::max(e, (uf.segment<3>(3 * i) - field(fluid.coordinates.row(i).transpose())).norm());
    return e;
  };
  const auto fluid = half_cylinder(48, 20, true, false);
  for (bool curved : {false, true}) {
    std::vector<double> e;
    for (int n : {4, 8, 16}) e.push_back(error(half_cylinder(n, n / 2, false, curved), fluid));
    const double order = std::log2(e[1] / e[2]);
    std::cout << (curved ? "quad9" : "quad4") << " faces: errors " << e[0] << ", " << e[1] << ", " << e[2] << ", order "
              << std::log2(e[0] / e[1]) << ", " << order << "\n";
    EXPECT_GT(order, curved ? 2.7 : 1.8) << (curved ? "quad9" : "quad4");
  }
  // RBF: affine fields exact at the fluid's nodes on the true cylinder.
  fsi::coupling::MappingSettings rbf;
  rbf.kind = fsi::coupling::MappingKind::RbfThinPlateSpline;
  const auto solid = half_cylinder(6, 4, false, false);
  const fsi::coupling::InterfaceMap map(solid, fluid, rbf);
  EXPECT_LT((map.to_fluid(affine(solid, kA, kB)) - affine(fluid, kA, kB)).lpNorm<Eigen::Infinity>(), 1e-9);
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
