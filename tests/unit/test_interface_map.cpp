// Interface mapping: consistent interpolation one way, its transpose the other way, so
// the power across the interface is identical on both sides.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <iostream>

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

// ---- radial basis functions (coupling.mapping: rbf-tps, rbf-wendland-c2) ----

using fsi::coupling::MappingKind;
using fsi::coupling::MappingSettings;

// The Turek-Hron flag's wet boundary (top, right end, bottom of [0.24899, 0.6] x [0.19, 0.21]),
// nx segments along each long edge and ny on the end, as one polyline from the top-left corner.
// grade in [0, 1): t -> t + grade sin(2 pi t) / (2 pi) along each edge (a graded fluid mesh,
// spacings in the ratio (1 + grade) / (1 - grade)).
fsi::InterfaceMeshData flag_boundary(int nx, int ny, double grade = 0, bool with_segments = true) {
  const double x0 = 0.24899, x1 = 0.6, y0 = 0.19, y1 = 0.21;
  std::vector<Eigen::Vector2d> pts;
  auto edge = [&](Eigen::Vector2d a, Eigen::Vector2d b, int n, bool first) {
    for (int i = first ? 0 : 1; i <= n; ++i) {
      double t = static_cast<double>(i) / n;
      t += grade * std::sin(2 * M_PI * t) / (2 * M_PI);
      pts.push_back(a + t * (b - a));
    }
  };
  edge({x0, y1}, {x1, y1}, nx, true);
  edge({x1, y1}, {x1, y0}, ny, false);
  edge({x1, y0}, {x0, y0}, nx, false);
  fsi::InterfaceMeshData d;
  d.coordinates.resize(static_cast<Eigen::Index>(pts.size()), 2);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    d.coordinates.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
    d.node_ids.push_back(static_cast<std::int64_t>(i));
    if (i > 0 && with_segments) d.segments.push_back({static_cast<int>(i) - 1, static_cast<int>(i)});
  }
  if (!with_segments) d.lumped_measure = Eigen::VectorXd::Constant(d.coordinates.rows(), 1.0);
  return d;
}

Eigen::VectorXd sample(const fsi::InterfaceMeshData& d, const std::function<Eigen::Vector2d(Eigen::Vector2d)>& u) {
  Eigen::VectorXd v(2 * d.coordinates.rows());
  for (Eigen::Index i = 0; i < d.coordinates.rows(); ++i) v.segment<2>(2 * i) = u(d.coordinates.row(i).transpose());
  return v;
}

MappingSettings rbf(MappingKind k, double radius = 0) {
  MappingSettings m;
  m.kind = k;
  m.support_radius = radius;
  return m;
}

// A linear term in the interpolant: every affine field u(x) = A x + c is mapped exactly, at fluid
// nodes on the solid's boundary or off it, so rigid translations and rigid rotations of any angle
// (u = (R - I)(x - x_c)) are. The nearest-segment projection is exact only on the boundary.
TEST(InterfaceMapRbf, ReproducesAffineFieldsAndRigidMotionsExactly) {
  const auto solid = flag_boundary(40, 2);
  auto fluid = flag_boundary(27, 3, 0.5);
  for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i)  // 1e-4 m off the boundary, outwards-ish
    fluid.coordinates(i, 1) += 1e-4 * (fluid.coordinates(i, 1) > 0.2 ? 1 : -1);
  const double angle = 30 * M_PI / 180;
  Eigen::Matrix2d rot;
  rot << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  const Eigen::Vector2d centre(0.2, 0.2);
  const std::vector<std::pair<const char*, std::function<Eigen::Vector2d(Eigen::Vector2d)>>> fields = {
      {"translation", [](Eigen::Vector2d) { return Eigen::Vector2d(0.01, -0.03); }},
      {"rotation 30 deg",
       [&](Eigen::Vector2d x) { return Eigen::Vector2d((rot - Eigen::Matrix2d::Identity()) * (x - centre)); }},
      {"affine", [](Eigen::Vector2d x) { return Eigen::Vector2d(2 * x[0] - 3 * x[1] + 1, 0.5 * x[0] + 4 * x[1] - 2); }},
  };
  for (const auto kind : {MappingKind::RbfThinPlateSpline, MappingKind::RbfWendlandC2}) {
    const fsi::coupling::InterfaceMap map(solid, fluid, rbf(kind));
    EXPECT_EQ(map.linear_terms(), 2);
    for (const auto& [name, u] : fields) {
      const Eigen::VectorXd exact = sample(fluid, u);
      const double err = (map.to_fluid(sample(solid, u)) - exact).lpNorm<Eigen::Infinity>();
      EXPECT_LT(err, 1e-12 * exact.lpNorm<Eigen::Infinity>()) << to_string(kind) << ", " << name;
    }
  }
  const fsi::coupling::InterfaceMap projection(solid, fluid);
  const auto& [name, u] = fields[1];
  EXPECT_GT((projection.to_fluid(sample(solid, u)) - sample(fluid, u)).lpNorm<Eigen::Infinity>(), 1e-5) << name;
}

// Forces by H^T: the sum of the forces and the interface work f_f . H v_s = F_s . v_s are the
// fluid's to round-off (H 1 = 1 from the constant term).
TEST(InterfaceMapRbf, ForcesAreConservative) {
  const auto solid = flag_boundary(40, 2);
  const auto fluid = flag_boundary(27, 3, 0.5);
  for (const auto kind : {MappingKind::RbfThinPlateSpline, MappingKind::RbfWendlandC2}) {
    const fsi::coupling::InterfaceMap map(solid, fluid, rbf(kind));
    const Eigen::VectorXd f_f = Eigen::VectorXd::Random(2 * fluid.coordinates.rows());
    const Eigen::VectorXd v_s = Eigen::VectorXd::Random(2 * solid.coordinates.rows());
    const Eigen::VectorXd f_s = map.to_solid(f_f);
    Eigen::Vector2d sum_f = Eigen::Vector2d::Zero(), sum_s = Eigen::Vector2d::Zero();
    for (Eigen::Index i = 0; i < fluid.coordinates.rows(); ++i) sum_f += f_f.segment<2>(2 * i);
    for (Eigen::Index i = 0; i < solid.coordinates.rows(); ++i) sum_s += f_s.segment<2>(2 * i);
    EXPECT_LT((sum_f - sum_s).lpNorm<Eigen::Infinity>(), 1e-12 * f_f.lpNorm<1>()) << to_string(kind);
    const double work_f = f_f.dot(map.to_fluid(v_s)), work_s = f_s.dot(v_s);
    EXPECT_LT(std::abs(work_f - work_s), 1e-13 * f_f.cwiseAbs().dot(map.to_fluid(v_s).cwiseAbs())) << to_string(kind);
    // The consistent mass M_G = H^T M_f H (a dense product for RBF): v_s . M_G v_s = v_f . M_f v_f.
    const fsi::NodalMatrix mf = fsi::coupling::nodal_interface_mass(fluid, Eigen::VectorXd());
    const fsi::NodalMatrix mg = map.mass_to_solid(mf);
    const Eigen::VectorXd w_s = Eigen::VectorXd::Random(solid.coordinates.rows());
    Eigen::VectorXd w2 = Eigen::VectorXd::Zero(2 * w_s.size());  // the x components
    for (Eigen::Index i = 0; i < w_s.size(); ++i) w2[2 * i] = w_s[i];
    const Eigen::VectorXd wf2 = map.to_fluid(w2);
    Eigen::VectorXd w_f(fluid.coordinates.rows());
    for (Eigen::Index i = 0; i < w_f.size(); ++i) w_f[i] = wf2[2 * i];
    EXPECT_NEAR(w_s.dot(mg * w_s), w_f.dot(mf * w_f), 1e-13 * w_f.dot(mf * w_f)) << to_string(kind);
  }
}

// Point clouds (no segments on either side), matching nodes in another order, nodes on a line
// (one linear term), one node (the constant only).
TEST(InterfaceMapRbf, PointCloudsLinesAndSingleNodes) {
  const auto solid = flag_boundary(20, 2, 0, false);
  auto fluid = solid;
  const Eigen::Index n = solid.coordinates.rows();
  for (Eigen::Index i = 0; i < n; ++i) fluid.coordinates.row(i) = solid.coordinates.row((7 * i + 3) % n);
  for (const auto kind : {MappingKind::RbfThinPlateSpline, MappingKind::RbfWendlandC2}) {
    const fsi::coupling::InterfaceMap map(solid, fluid, rbf(kind));
    EXPECT_TRUE(map.conforming());
    EXPECT_LT(map.permutation_error(), 1e-10) << to_string(kind);
    const Eigen::VectorXd v = Eigen::VectorXd::Random(2 * n);
    const Eigen::VectorXd vf = map.to_fluid(v);
    for (Eigen::Index i = 0; i < n; ++i) EXPECT_NEAR(vf[2 * i], v[2 * ((7 * i + 3) % n)], 1e-10);

    const auto line_s = polyline(7, 0, 2, 0), line_f = polyline(23, 0, 2, 1e-3);
    const fsi::coupling::InterfaceMap on_line(line_s, line_f, rbf(kind));
    EXPECT_EQ(on_line.linear_terms(), 1);
    auto u = [](Eigen::Vector2d x) { return Eigen::Vector2d(2 * x[0] + 1, -3 * x[0]); };
    EXPECT_LT((on_line.to_fluid(sample(line_s, u)) - sample(line_f, u)).lpNorm<Eigen::Infinity>(), 1e-12);

    fsi::InterfaceMeshData one;
    one.coordinates = Eigen::MatrixX2d::Constant(1, 2, 0.5);
    one.lumped_measure = Eigen::VectorXd::Constant(1, 1.0);
    const fsi::coupling::InterfaceMap single(one, one, rbf(kind));
    EXPECT_EQ(single.linear_terms(), 0);
    EXPECT_NEAR(single.to_fluid(Eigen::Vector2d(1, 2))[1], 2.0, 1e-15);
  }
  fsi::InterfaceMeshData twice = polyline(5, 0, 1, 0);
  twice.coordinates.row(1) = twice.coordinates.row(0);
  EXPECT_THROW(fsi::coupling::InterfaceMap(twice, polyline(9, 0, 1, 0), rbf(MappingKind::RbfThinPlateSpline)),
               std::invalid_argument);
}

// A smooth field from the solid's uniform discretisation of the flag boundary to a graded,
// non-matching fluid one (spacings 1:3 along each edge), at four resolutions: the solid 40 x 2,
// 80 x 4, 160 x 8, 320 x 16 segments (long edges x end), the fluid 27 x 3 ... 216 x 24. The
// largest error at the fluid's nodes relative to the field's largest value, and the order of
// convergence between successive resolutions. Nearest-segment: second order (linear
// interpolation). Thin-plate splines: 2.6-3.7 here. Wendland C2 with the default radius (50 x
// the spacing, so it shrinks with the mesh: the stationary setting) converges like the others
// at first and then stalls at 1.5e-5, where a fixed radius would keep converging (at a
// condition number growing 16x per halving of the spacing here).
TEST(InterfaceMapRbf, SmoothFieldErrorAndOrder) {
  auto u = [](Eigen::Vector2d x) {
    const double xi = (x[0] - 0.24899) / 0.35101, eta = (x[1] - 0.2) / 0.35101;
    return Eigen::Vector2d(std::sin(2 * M_PI * xi) + eta, std::cos(M_PI * xi) * std::exp(4 * eta));
  };
  struct Row {
    const char* name;
    MappingSettings m;
    std::array<double, 4> expected;
    std::array<double, 4> err{};
  };
  std::vector<Row> rows = {
      {"nearest-segment", {}, {2.6693e-3, 6.4533e-4, 1.7149e-4, 4.2542e-5}},
      {"rbf-tps", rbf(MappingKind::RbfThinPlateSpline), {1.0543e-3, 7.8448e-5, 1.0503e-5, 1.7304e-6}},
      {"rbf-wendland-c2", rbf(MappingKind::RbfWendlandC2), {4.4837e-4, 1.0449e-4, 1.4043e-5, 1.4621e-5}}};
  for (int level = 0; level < 4; ++level) {
    const int k = 1 << level;
    const auto solid = flag_boundary(40 * k, 2 * k), fluid = flag_boundary(27 * k, 3 * k, 0.5);
    const Eigen::VectorXd exact = sample(fluid, u);
    for (auto& row : rows) {
      const fsi::coupling::InterfaceMap map(solid, fluid, row.m);
      row.err[level] =
          (map.to_fluid(sample(solid, u)) - exact).lpNorm<Eigen::Infinity>() / exact.lpNorm<Eigen::Infinity>();
    }
  }
  for (const auto& row : rows) {
    std::cout << "[ smooth field ] " << row.name << ":";
    for (int level = 0; level < 4; ++level) {
      std::cout << " " << row.err[level];
      if (level > 0) std::cout << " (order " << std::log2(row.err[level - 1] / row.err[level]) << ")";
      EXPECT_NEAR(row.err[level], row.expected[level], 1e-3 * row.expected[level]) << row.name << " level " << level;
    }
    std::cout << "\n";
  }
  // Both RBFs below the projection's error at every resolution but the finest (Wendland's stall).
  for (int level = 0; level < 4; ++level) EXPECT_LT(rows[1].err[level], rows[0].err[level]);
  for (int level = 0; level < 3; ++level) EXPECT_LT(rows[2].err[level], rows[0].err[level]);
}

}  // namespace
