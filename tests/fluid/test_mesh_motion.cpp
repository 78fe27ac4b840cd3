// Mesh motion options: pseudo-elastic extension and the incremental operator (rebuilt on
// the accepted mesh) against the one-shot harmonic extension, on a large rigid rotation.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "fsi/fluid/mesh_motion.hpp"
#include "fsi/fluid/p1_element.hpp"

using namespace fsi::fluid;

namespace {

// Nodes of the central block |x - 0.5|, |y - 0.5| <= 0.15 move as a rigid body.
std::vector<int> block_nodes(const FluidMesh& mesh) {
  std::vector<int> nodes;
  for (int i = 0; i < mesh.node_count(); ++i)
    if (std::abs(mesh.nodes(i, 0) - 0.5) <= 0.15 + 1e-12 && std::abs(mesh.nodes(i, 1) - 0.5) <= 0.15 + 1e-12)
      nodes.push_back(i);
  return nodes;
}

Eigen::VectorXd rotation(const FluidMesh& mesh, const std::vector<int>& nodes, double angle) {
  Eigen::VectorXd d(2 * static_cast<Eigen::Index>(nodes.size()));
  const Eigen::Rotation2Dd r(angle);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const Eigen::Vector2d x = mesh.nodes.row(nodes[k]).transpose() - Eigen::Vector2d(0.5, 0.5);
    d.segment<2>(2 * static_cast<Eigen::Index>(k)) = r * x - x;
  }
  return d;
}

double min_area(const FluidMesh& mesh, const Eigen::MatrixX2d& displacement) {
  double smallest = 1e300;
  for (int e = 0; e < mesh.triangle_count(); ++e) {
    Eigen::Matrix<double, 3, 2> x;
    for (int k = 0; k < 3; ++k)
      x.row(k) = mesh.nodes.row(mesh.triangles(e, k)) + displacement.row(mesh.triangles(e, k));
    smallest = std::min(smallest, triangle_geometry(x).area);
  }
  return smallest;
}

MeshMotionOptions options(MeshMotionOptions::Method method, bool incremental) {
  MeshMotionOptions o;
  o.method = method;
  o.incremental = incremental;
  o.stiffening = 1.0;
  return o;
}

TEST(MeshMotionOptions, PrescribedNodesFollowExactlyAndFixedNodesStay) {
  const auto mesh = FluidMesh::rectangle(0, 1, 0, 1, 16, 16);
  const auto block = block_nodes(mesh);
  const auto outer = mesh.boundary_nodes({"left", "right", "bottom", "top"});
  for (auto method : {MeshMotionOptions::Method::Harmonic, MeshMotionOptions::Method::Elastic}) {
    MeshMotion motion(mesh, block, outer, options(method, true));
    const auto d = rotation(mesh, block, 0.2);
    const auto u = motion.extend(d);
    for (std::size_t k = 0; k < block.size(); ++k)
      EXPECT_LT((u.row(block[k]).transpose() - d.segment<2>(2 * static_cast<Eigen::Index>(k))).norm(), 1e-14);
    for (int i : outer) EXPECT_EQ(u.row(i).norm(), 0.0);
    // Incremental: accepting a state and extending it again reproduces it.
    motion.accept(d);
    EXPECT_LT((motion.extend(d) - u).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(MeshMotionOptions, IncrementalElasticSurvivesALargeRotationThatTanglesTheOneShotHarmonicMesh) {
  const auto mesh = FluidMesh::rectangle(0, 1, 0, 1, 24, 24);
  const auto block = block_nodes(mesh);
  const auto outer = mesh.boundary_nodes({"left", "right", "bottom", "top"});
  const double total = 70.0 * M_PI / 180.0;
  const int steps = 14;
  MeshMotion one_shot(mesh, block, outer, options(MeshMotionOptions::Method::Harmonic, false));
  MeshMotion incremental(mesh, block, outer, options(MeshMotionOptions::Method::Elastic, true));
  Eigen::MatrixX2d u_inc;
  for (int s = 1; s <= steps; ++s) {
    const auto d = rotation(mesh, block, total * s / steps);
    u_inc = incremental.extend(d);
    ASSERT_GT(min_area(mesh, u_inc), 0.0) << "incremental elastic tangled at step " << s;
    incremental.accept(d);
  }
  const double reference_area = 1.0 / (24 * 24 * 2);
  EXPECT_GT(min_area(mesh, u_inc), 0.05 * reference_area);
  EXPECT_LT(min_area(mesh, one_shot.extend(rotation(mesh, block, total))), 0.0)
      << "the one-shot harmonic extension was expected to tangle at 70 degrees";
}

}  // namespace
