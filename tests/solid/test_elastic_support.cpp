// Elastic supports (elastic_support.hpp): a block resting on a normal support under a dead
// traction settles by exactly T / k_s (closed form: the homogeneous state is in the element
// space); the support's normals on a tube's outer face are radial; the tangent is the exact
// derivative of the residual; the scene keys refuse what they cannot use.
#include <gtest/gtest.h>

#include <cmath>

#include "fsi/solid/elastic_support.hpp"
#include "fsi/solid/solid_system.hpp"

using namespace fsi::solid;

namespace {

// A block [0, 1] x [0, 0.2] (10 x 4 Q4, or 10 x 4 x 2 Hex8 of depth 0.2) on a normal support of
// stiffness k on its bottom, x held on its left face (z on back and front in 3D), a dead
// traction T pressing on its top.
struct Block {
  SolidMesh mesh;
  std::vector<char> fixed;
  std::unique_ptr<SolidSystem> system;
  Eigen::VectorXd load;
};

Block make_block(int dim, double k, double T, bool normal_only) {
  Block b;
  b.mesh = dim == 2 ? rectangle_mesh(0, 0, 1, 0.2, 10, 4)
                    : box_mesh(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0.2, 0.2), 10, 4, 2);
  const int n = b.mesh.num_nodes();
  b.fixed.assign(static_cast<std::size_t>(dim * n), 0);
  for (int node : b.mesh.facet_nodes({"left"})) b.fixed[static_cast<std::size_t>(dim * node)] = 1;
  if (dim == 3)
    for (int node : b.mesh.facet_nodes({"back", "front"})) b.fixed[static_cast<std::size_t>(3 * node + 2)] = 1;
  const auto c = ElasticConstants::from_youngs(1e4, 0.3);
  if (dim == 2)
    b.system = std::make_unique<SolidSystem>(b.mesh, make_material<2>("neo_hookean", c), 1.0, b.fixed);
  else
    b.system = std::make_unique<SolidSystem>(b.mesh, make_material<3>("neo_hookean", c), 1.0, b.fixed);
  b.system->set_support(
      std::make_shared<ElasticSupport>(b.mesh, std::vector<SupportSpec>{{b.mesh.facets({"bottom"}), k, normal_only}}));
  const Eigen::VectorXd top = lumped_facet_measure(b.mesh, b.mesh.facets({"top"}));
  b.load = Eigen::VectorXd::Zero(dim * n);
  for (int i = 0; i < n; ++i) b.load(dim * i + 1) = -T * top(i);
  return b;
}

}  // namespace

class SupportedBlock : public ::testing::TestWithParam<int> {};

TEST_P(SupportedBlock, SettlesByTractionOverStiffness) {
  const int dim = GetParam();
  const double k = 2e5, T = 50;
  Block b = make_block(dim, k, T, true);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(b.system->num_dofs());
  NewtonOptions opt;
  opt.residual_tolerance = 1e-13;
  opt.increment_tolerance = 0;
  ASSERT_TRUE(b.system->solve(d, b.load, TimeTerms{}, opt).converged);
  for (int node : b.mesh.facet_nodes({"bottom"})) EXPECT_NEAR(d(dim * node + 1), -T / k, 1e-9 * T / k) << node;
  // The support carries the whole load: its force is T |top| upwards.
  EXPECT_NEAR(b.system->support()->force(d)(1), T * (dim == 2 ? 1.0 : 0.2), 1e-9 * T);
}

// The residual's derivative by central differences equals the assembled tangent's action, with
// the support in every direction (the block can no longer move freely sideways).
TEST_P(SupportedBlock, TangentIsTheResidualsDerivative) {
  const int dim = GetParam();
  for (bool normal_only : {true, false}) {
    Block b = make_block(dim, 2e5, 50, normal_only);
    const int n = b.system->num_dofs();
    Eigen::VectorXd d = Eigen::VectorXd::Zero(n), dir(n);
    for (int i = 0; i < n; ++i) {
      d(i) = 1e-3 * std::sin(1.3 * i);
      dir(i) = b.system->fixed()[static_cast<std::size_t>(i)] ? 0.0 : std::cos(0.7 * i);
    }
    SparseMatrix K;
    Eigen::VectorXd r_free;
    b.system->assemble(d, b.load, TimeTerms{}, K, r_free);
    Eigen::VectorXd dir_free(b.system->num_free());
    int f = 0;
    for (int i = 0; i < n; ++i)
      if (!b.system->fixed()[static_cast<std::size_t>(i)]) dir_free(f++) = dir(i);
    const double h = 1e-6;
    const Eigen::VectorXd rp = b.system->residual(d + h * dir, b.load, TimeTerms{});
    const Eigen::VectorXd rm = b.system->residual(d - h * dir, b.load, TimeTerms{});
    Eigen::VectorXd fd_free(b.system->num_free());
    f = 0;
    for (int i = 0; i < n; ++i)
      if (!b.system->fixed()[static_cast<std::size_t>(i)]) fd_free(f++) = (rp(i) - rm(i)) / (2 * h);
    const Eigen::VectorXd Kd = K * dir_free;
    EXPECT_LT((Kd - fd_free).norm(), 1e-6 * Kd.norm()) << (normal_only ? "normal" : "all");
  }
}

INSTANTIATE_TEST_SUITE_P(Dimensions, SupportedBlock, ::testing::Values(2, 3));

// On a tube's outer face the normals are radial: an axial or a tangential displacement meets no
// support force, a uniform radial one a force k A per node along the radius.
TEST(ElasticSupport, NormalsOnATubeAreRadial) {
  const SolidMesh mesh = tube_mesh(Eigen::Vector3d::Zero(), 0.5, 0.6, 2.0, 16, 2, 4);
  const double k = 3.0;
  const ElasticSupport s(mesh, {{mesh.facets({"outer"}), k, true}});
  const Eigen::VectorXd area = lumped_facet_measure(mesh, mesh.facets({"outer"}));
  const int n = mesh.num_nodes();
  Eigen::VectorXd axial = Eigen::VectorXd::Zero(3 * n), tangential = axial, radial = axial;
  for (int a = 0; a < n; ++a) {
    const double x = mesh.nodes(a, 0), y = mesh.nodes(a, 1), r = std::hypot(x, y);
    axial(3 * a + 2) = 1;
    tangential.segment<3>(3 * a) << -y / r, x / r, 0;
    radial.segment<3>(3 * a) << x / r, y / r, 0;
  }
  Eigen::VectorXd r0 = Eigen::VectorXd::Zero(3 * n), r1 = r0, r2 = r0;
  s.add_to_residual(axial, r0);
  s.add_to_residual(tangential, r1);
  s.add_to_residual(radial, r2);
  EXPECT_LT(r0.norm(), 1e-12);
  EXPECT_LT(r1.norm(), 1e-12);
  for (int a = 0; a < n; ++a) {
    EXPECT_NEAR(r2.segment<3>(3 * a).norm(), k * area(a), 1e-12) << a;
    EXPECT_NEAR(r2.segment<3>(3 * a).dot(radial.segment<3>(3 * a)), k * area(a), 1e-12) << a;
  }
  EXPECT_THROW(ElasticSupport(mesh, {{mesh.facets({"outer"}), 0.0, true}}), std::invalid_argument);
}
