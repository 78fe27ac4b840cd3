// The mesh-quality monitor on triangles whose quality is known in closed form.
#include <gtest/gtest.h>

#include <cmath>

#include "fsi/fluid/mesh_quality.hpp"

namespace {

using fsi::fluid::FluidMesh;
using fsi::fluid::mesh_quality;

FluidMesh one_triangle(const Eigen::Matrix<double, 3, 2>& p) {
  FluidMesh m;
  m.nodes = p;
  m.triangles.resize(1, 3);
  m.triangles << 0, 1, 2;
  return m;
}

TEST(MeshQuality, EquilateralRightAndInvertedTriangles) {
  Eigen::Matrix<double, 3, 2> p;
  p << 0, 0, 1, 0, 0.5, std::sqrt(3.0) / 2;
  auto q = mesh_quality(one_triangle(p), p);
  EXPECT_NEAR(q.min_scaled_jacobian, 1.0, 1e-14);
  EXPECT_NEAR(q.max_angle_deg, 60.0, 1e-12);
  EXPECT_EQ(q.inverted, 0);
  p << 0, 0, 1, 0, 0, 1;  // right isosceles: corners 90, 45, 45 -> sin 45 * 2 / sqrt(3)
  q = mesh_quality(one_triangle(p), p);
  EXPECT_NEAR(q.min_scaled_jacobian, std::sqrt(0.5) * 2 / std::sqrt(3.0), 1e-14);
  EXPECT_NEAR(q.max_angle_deg, 90.0, 1e-12);
  const FluidMesh m = one_triangle(p);
  Eigen::MatrixX2d flipped = p;
  flipped(2, 1) = -1;  // the third node through the opposite edge: inverted
  q = mesh_quality(m, flipped);
  EXPECT_LT(q.min_scaled_jacobian, 0);
  EXPECT_EQ(q.max_angle_deg, 180.0);
  EXPECT_EQ(q.inverted, 1);
  EXPECT_EQ(q.worst_element, 0);
}

TEST(MeshQuality, ARectangleAndItsWorstElement) {
  const FluidMesh m = FluidMesh::rectangle(0, 2, 0, 1, 4, 2);
  Eigen::MatrixX2d x = m.nodes;
  auto q = mesh_quality(m, x);
  EXPECT_NEAR(q.min_scaled_jacobian, std::sqrt(0.5) * 2 / std::sqrt(3.0), 1e-12);  // right isosceles cells
  EXPECT_NEAR(q.max_angle_deg, 90.0, 1e-10);
  // Squeeze one interior node towards a neighbour: the worst element is one of its triangles.
  int centre = -1;
  for (int i = 0; i < m.node_count(); ++i)
    if (std::abs(x(i, 0) - 1.0) < 1e-12 && std::abs(x(i, 1) - 0.5) < 1e-12) centre = i;
  ASSERT_GE(centre, 0);
  x(centre, 0) += 0.45;
  q = mesh_quality(m, x);
  EXPECT_LT(q.min_scaled_jacobian, 0.2);
  EXPECT_GT(q.max_angle_deg, 120.0);
  bool touches = false;
  for (int k = 0; k < 3; ++k) touches = touches || m.triangles(q.worst_element, k) == centre;
  EXPECT_TRUE(touches);
}

TEST(MeshQuality, CurvedSixNodeTriangles) {
  const FluidMesh m = FluidMesh::rectangle(0, 1, 0, 1, 1, 1).quadratic_from_linear();
  Eigen::MatrixX2d x = m.nodes;
  auto q = mesh_quality(m, x);
  EXPECT_NEAR(q.min_curved_jacobian, 1.0, 1e-12);  // straight edges: the affine Jacobian
  // Move the midpoint of the bottom edge (a boundary edge of one triangle) inwards by s:
  // det J along that edge varies linearly, its minimum over the straight det J is 1 - 4 s / h
  // at a corner (h = 1 here, the height of that triangle over the edge is 1).
  int mid = -1;
  for (int i = m.vertices(); i < m.node_count(); ++i)
    if (std::abs(x(i, 0) - 0.5) < 1e-12 && std::abs(x(i, 1)) < 1e-12) mid = i;
  ASSERT_GE(mid, 0);
  x(mid, 1) = 0.1;
  q = mesh_quality(m, x);
  EXPECT_NEAR(q.min_curved_jacobian, 1 - 4 * 0.1, 1e-12);
  EXPECT_EQ(q.inverted, 0);
  x(mid, 1) = 0.3;  // past a quarter of the height: the element folds at the corners
  q = mesh_quality(m, x);
  EXPECT_LT(q.min_curved_jacobian, 0);
  EXPECT_EQ(q.inverted, 1);
}

}  // namespace
