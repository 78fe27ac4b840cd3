// Interface mapping: consistent interpolation one way, its transpose the other way, so
// the power across the interface is identical on both sides.
#include <gtest/gtest.h>

#include "fsi/coupling/interface_map.hpp"

namespace {

fsi::InterfaceMeshData polyline(int n, double x0, double x1, double y) {
  fsi::InterfaceMeshData d;
  d.coordinates.resize(n, 2);
  for (int i = 0; i < n; ++i) {
    d.coordinates(i, 0) = x0 + (x1 - x0) * i / (n - 1);
    d.coordinates(i, 1) = y;
    d.node_ids.push_back(i);
    if (i > 0) d.segments.push_back({i - 1, i});
  }
  return d;
}

TEST(InterfaceMap, MatchingMeshesGiveIdentity) {
  const auto s = polyline(5, 0, 1, 0);
  fsi::coupling::InterfaceMap map(s, s);
  Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(10, -1, 3);
  EXPECT_LT((map.to_fluid(v) - v).norm(), 1e-15);
  EXPECT_LT((map.to_solid(v) - v).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(map.max_gap(), 0.0);
}

TEST(InterfaceMap, InterpolatesLinearFieldsExactlyOnNonMatchingNodes) {
  const auto solid = polyline(4, 0, 1, 0);
  const auto fluid = polyline(11, 0, 1, 1e-3);  // offset: a small gap
  fsi::coupling::InterfaceMap map(solid, fluid);
  Eigen::VectorXd u(8);
  for (int i = 0; i < 4; ++i) {
    const double x = solid.coordinates(i, 0);
    u[2 * i] = 2 * x + 1;
    u[2 * i + 1] = -3 * x;
  }
  const Eigen::VectorXd uf = map.to_fluid(u);
  for (int i = 0; i < 11; ++i) {
    const double x = fluid.coordinates(i, 0);
    EXPECT_NEAR(uf[2 * i], 2 * x + 1, 1e-14);
    EXPECT_NEAR(uf[2 * i + 1], -3 * x, 1e-14);
  }
  EXPECT_NEAR(map.max_gap(), 1e-3, 1e-15);
}

TEST(InterfaceMap, PowerIsConservedAcrossTheInterface) {
  const auto solid = polyline(7, 0, 2, 0);
  const auto fluid = polyline(23, 0, 2, 0);
  fsi::coupling::InterfaceMap map(solid, fluid);
  const Eigen::VectorXd v_s = Eigen::VectorXd::Random(14);
  const Eigen::VectorXd f_f = Eigen::VectorXd::Random(46);
  const double fluid_power = f_f.dot(map.to_fluid(v_s));
  const double solid_power = map.to_solid(f_f).dot(v_s);
  EXPECT_NEAR(fluid_power, solid_power, 1e-13 * std::abs(fluid_power));
  // Total force is preserved too (the interpolation weights sum to one).
  Eigen::Vector2d sum_f = Eigen::Vector2d::Zero(), sum_s = Eigen::Vector2d::Zero();
  const Eigen::VectorXd f_s = map.to_solid(f_f);
  for (int i = 0; i < 23; ++i) sum_f += f_f.segment<2>(2 * i);
  for (int i = 0; i < 7; ++i) sum_s += f_s.segment<2>(2 * i);
  EXPECT_LT((sum_f - sum_s).norm(), 1e-13);
}

TEST(InterfaceMap, InterfaceMassIntegratesLengthInCurrentConfiguration) {
  const auto s = polyline(5, 0, 2, 0);
  Eigen::VectorXd ones = Eigen::VectorXd::Zero(10);
  for (int i = 0; i < 5; ++i) ones[2 * i] = 1;
  // int 1 * 1 dgamma = length = 2 in the reference configuration.
  EXPECT_NEAR(ones.dot(fsi::coupling::interface_mass(s, Eigen::VectorXd()) * ones), 2.0, 1e-14);
  // Stretched uniformly by 50 % in x: length 3.
  Eigen::VectorXd d = Eigen::VectorXd::Zero(10);
  for (int i = 0; i < 5; ++i) d[2 * i] = 0.5 * s.coordinates(i, 0);
  EXPECT_NEAR(ones.dot(fsi::coupling::interface_mass(s, d) * ones), 3.0, 1e-14);
}

TEST(InterfaceMap, PointInterfaceUsesLumpedMeasure) {
  fsi::InterfaceMeshData p;
  p.coordinates = Eigen::MatrixX2d::Zero(1, 2);
  p.node_ids = {0};
  p.lumped_measure = Eigen::VectorXd::Constant(1, 2.5);
  const auto m = fsi::coupling::interface_mass(p, Eigen::VectorXd());
  EXPECT_DOUBLE_EQ(m.coeff(0, 0), 2.5);
  EXPECT_DOUBLE_EQ(m.coeff(1, 1), 2.5);
  fsi::coupling::InterfaceMap map(p, p);
  EXPECT_DOUBLE_EQ(map.to_fluid(Eigen::Vector2d(1, 2))[1], 2.0);
}

TEST(InterfaceMap, MissingInterfaceOnOneSideIsAnError) {
  fsi::InterfaceMeshData empty;
  EXPECT_THROW(fsi::coupling::InterfaceMap(polyline(3, 0, 1, 0), empty), std::invalid_argument);
}

// Conforming interface: the same nodes in another order (the fluid's node numbering) is a
// permutation; a node 2e-7 off (the Turek-Hron flag root, solid origin 0.24899 vs the
// cylinder's 0.2489898) or extra midpoints (the P2 fluid) is not.
TEST(InterfaceMap, DetectsConformingInterfaces) {
  const auto s = polyline(9, 0.25, 0.6, 0.19);
  fsi::InterfaceMeshData f = s;
  for (int i = 0; i < 9; ++i) f.coordinates.row(i) = s.coordinates.row((5 * i + 2) % 9);  // a permutation
  {
    fsi::coupling::InterfaceMap map(s, f);
    EXPECT_TRUE(map.conforming());
    EXPECT_EQ(map.coincident_nodes(), 9);
    EXPECT_LT(map.max_gap(), 1e-15);
    EXPECT_LT(map.permutation_error(), 1e-12);
    Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(18, -1, 3);
    const Eigen::VectorXd vf = map.to_fluid(v);
    for (int i = 0; i < 9; ++i) EXPECT_NEAR(vf[2 * i + 1], v[2 * ((5 * i + 2) % 9) + 1], 1e-12);
  }
  {
    fsi::InterfaceMeshData g = f;
    g.coordinates(0, 0) += 1e-10;  // within 1e-9 of the size (0.35): still the same node
    EXPECT_TRUE(fsi::coupling::InterfaceMap(s, g).conforming());
    g.coordinates(0, 0) += 2e-7;
    fsi::coupling::InterfaceMap map(s, g);
    EXPECT_FALSE(map.conforming());
    EXPECT_EQ(map.coincident_nodes(), 8);
    EXPECT_DOUBLE_EQ(map.permutation_error(), 0.0);
  }
  {
    const auto p2 = polyline(17, 0.25, 0.6, 0.19);  // vertices and midpoints
    fsi::coupling::InterfaceMap map(s, p2);
    EXPECT_FALSE(map.conforming());
    EXPECT_EQ(map.coincident_nodes(), 9);
    EXPECT_LT(map.max_gap(), 1e-15);
  }
  {
    fsi::InterfaceMeshData twice = f;  // as many nodes, but two on the same solid node
    twice.coordinates.row(1) = twice.coordinates.row(0);
    EXPECT_FALSE(fsi::coupling::InterfaceMap(s, twice).conforming());
  }
}

}  // namespace
