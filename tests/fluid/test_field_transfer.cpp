// Moving nodal fields between fluid meshes: exact for the fields the elements hold exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fsi/fluid/field_transfer.hpp"

namespace {

using namespace fsi::fluid;

Eigen::MatrixXd linear_field(const Eigen::MatrixX2d& x) {
  Eigen::MatrixXd f(x.rows(), 2);
  f.col(0) = 1.5 + 2.0 * x.col(0).array() - 0.7 * x.col(1).array();
  f.col(1) = -0.3 + 0.25 * x.col(0).array() + 3.0 * x.col(1).array();
  return f;
}

Eigen::VectorXd quadratic_field(const Eigen::MatrixX2d& x) {
  return (0.5 + x.col(0).array() * x.col(0).array() - 2.0 * x.col(0).array() * x.col(1).array() +
          0.3 * x.col(1).array().square() + x.col(1).array())
      .matrix();
}

TEST(FieldTransfer, LinearFieldsMoveExactlyBetweenP1Meshes) {
  const FluidMesh a = FluidMesh::rectangle(0, 2, 0, 1, 4, 3), b = FluidMesh::rectangle(0, 2, 0, 1, 7, 5);
  const MeshLocator locator(a, a.nodes);
  TransferReport report;
  const Eigen::MatrixXd moved = interpolate_field(locator, a, linear_field(a.nodes), b.nodes, &report);
  EXPECT_LT((moved - linear_field(b.nodes)).cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_EQ(report.points, b.node_count());
  EXPECT_EQ(report.outside, 0);
}

TEST(FieldTransfer, QuadraticFieldsMoveExactlyBetweenP2MeshesAndP1FieldsOnTheirVertices) {
  const FluidMesh a = FluidMesh::rectangle(0, 2, 0, 1, 3, 2).quadratic_from_linear();
  const FluidMesh b = FluidMesh::rectangle(0, 2, 0, 1, 6, 5).quadratic_from_linear();
  const MeshLocator locator(a, a.nodes);
  const Eigen::MatrixXd moved = interpolate_field(locator, a, quadratic_field(a.nodes), b.nodes);
  EXPECT_LT((moved.col(0) - quadratic_field(b.nodes)).cwiseAbs().maxCoeff(), 1e-12);
  // A pressure-like field on the vertices only: P1 on the same triangles.
  const Eigen::MatrixX2d va = a.nodes.topRows(a.vertices());
  const Eigen::MatrixXd p = interpolate_field(locator, a, linear_field(va), b.nodes);
  EXPECT_LT((p - linear_field(b.nodes)).cwiseAbs().maxCoeff(), 1e-12);
}

// On curved (moved) 6-node triangles the isoparametric map is inverted by Newton's method:
// interpolating the nodes' own positions returns the query point.
TEST(FieldTransfer, CurvedElementsAreInvertedExactly) {
  const FluidMesh a = FluidMesh::rectangle(0, 2, 0, 1, 4, 3).quadratic_from_linear();
  Eigen::MatrixX2d x = a.nodes;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    x(i, 0) += 0.04 * std::sin(3.0 * a.nodes(i, 1));
    x(i, 1) += 0.03 * std::sin(2.5 * a.nodes(i, 0));
  }
  const MeshLocator locator(a, x);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Points inside the moved mesh: images of random reference points of random elements.
  Eigen::MatrixX2d points(200, 2);
  for (int q = 0; q < 200; ++q) {
    const int e = static_cast<int>(u(rng) * a.triangle_count()) % a.triangle_count();
    double s = u(rng), t = u(rng);
    if (s + t > 1) s = 1 - s, t = 1 - t;
    const double l0 = 1 - s - t;
    const double N[6] = {l0 * (2 * l0 - 1), s * (2 * s - 1), t * (2 * t - 1), 4 * l0 * s, 4 * s * t, 4 * t * l0};
    const auto nodes = a.element_nodes6(e);
    points.row(q).setZero();
    for (int k = 0; k < 6; ++k) points.row(q) += N[k] * x.row(nodes(k));
  }
  TransferReport report;
  const Eigen::MatrixXd back = interpolate_field(locator, a, Eigen::MatrixXd(x), points, &report);
  EXPECT_LT((back - Eigen::MatrixXd(points)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(report.outside, 0);
}

TEST(FieldTransfer, PointsOutsideTakeTheNearestBoundaryValueAndAreCounted) {
  const FluidMesh a = FluidMesh::rectangle(0, 2, 0, 1, 4, 3);
  const MeshLocator locator(a, a.nodes);
  Eigen::MatrixX2d points(2, 2);
  points << 1.3, 1.01,  // 0.01 above the top edge
      0.7, 0.4;         // inside
  TransferReport report;
  const Eigen::MatrixXd f = interpolate_field(locator, a, linear_field(a.nodes), points, &report);
  EXPECT_EQ(report.outside, 1);
  EXPECT_NEAR(report.max_distance, 0.01, 1e-12);
  Eigen::MatrixX2d on_edge(1, 2);
  on_edge << 1.3, 1.0;
  EXPECT_LT((f.row(0) - linear_field(on_edge).row(0)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_THROW(interpolate_field(locator, a, Eigen::MatrixXd::Zero(5, 1), points), std::invalid_argument);
}

}  // namespace
