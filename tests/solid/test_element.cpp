// Q4 element and assembled system: tangent vs finite differences, mass, patch test,
// convergence rate of a manufactured solution.
#include <gtest/gtest.h>

#include <cmath>

#include "fsi/solid/element.hpp"
#include "fsi/solid/solid_system.hpp"

using namespace fsi::solid;

namespace {
ElementCoords distorted_quad() {
  ElementCoords X;
  X << 0.0, 0.0, 1.2, 0.1, 1.0, 0.9, -0.1, 1.1;
  return X;
}
}  // namespace

TEST(Q4, ShapeFunctionsPartitionOfUnity) {
  for (double xi : {-1.0, -0.3, 0.5})
    for (double eta : {-0.7, 0.0, 1.0}) {
      EXPECT_NEAR(q4_shape(xi, eta).sum(), 1.0, 1e-15);
      EXPECT_NEAR(q4_shape_derivatives(xi, eta).colwise().sum().norm(), 0.0, 1e-15);
    }
}

class ElementTangent : public ::testing::TestWithParam<std::string> {};

// The consistent tangent is the derivative of the internal force; the forces are
// self-equilibrated. For the enhanced-strain element the tangent is the condensed one (the
// enhanced parameters re-solved at every state).
void check_tangent(const std::string& law,
                   ElementState (*element)(const ElementCoords&, const ElementVector&, const Material&, bool)) {
  const auto mat = make_material(law, ElasticConstants::from_youngs(1e3, 0.35));
  const ElementCoords X = distorted_quad();
  ElementVector u;
  u << 0.0, 0.0, 0.15, 0.05, 0.1, 0.2, -0.05, 0.1;  // finite deformation
  const ElementState s = element(X, u, *mat, true);
  ASSERT_GT(s.min_det_F, 0);
  EXPECT_LT((s.tangent - s.tangent.transpose()).norm(), 1e-10 * s.tangent.norm());
  ElementMatrix fd;
  const double h = 1e-7;
  for (int j = 0; j < 8; ++j) {
    ElementVector up = u, um = u;
    up(j) += h;
    um(j) -= h;
    fd.col(j) = (element(X, up, *mat, false).internal_force - element(X, um, *mat, false).internal_force) / (2 * h);
  }
  EXPECT_LT((fd - s.tangent).norm(), 1e-6 * s.tangent.norm());
  EXPECT_NEAR(s.internal_force(Eigen::seq(0, 7, 2)).sum(), 0.0, 1e-10 * s.internal_force.norm());
  EXPECT_NEAR(s.internal_force(Eigen::seq(1, 7, 2)).sum(), 0.0, 1e-10 * s.internal_force.norm());
}

TEST_P(ElementTangent, MatchesFiniteDifferenceOfInternalForce) { check_tangent(GetParam(), q4_internal_force); }

TEST_P(ElementTangent, EnhancedStrainCondensedTangentMatchesFiniteDifferences) {
  check_tangent(GetParam(), q4_eas_internal_force);
}

INSTANTIATE_TEST_SUITE_P(Laws, ElementTangent, ::testing::Values("saint_venant_kirchhoff", "neo_hookean"));

// Patch test: under a homogeneous deformation the enhanced strains vanish and the element is
// the Q4 (the modes are orthogonal to constant stress on any parallelogram and, with the
// centre-Jacobian scaling, on a distorted quad too).
TEST(Q4Eas, HomogeneousDeformationGivesTheQ4Forces) {
  const auto mat = make_material("neo_hookean", ElasticConstants::from_youngs(1e3, 0.3));
  const ElementCoords X = distorted_quad();
  Eigen::Matrix2d H;
  H << 0.1, 0.05, -0.03, 0.08;
  ElementVector u;
  for (int a = 0; a < 4; ++a) u.segment<2>(2 * a) = H * X.row(a).transpose();
  const ElementState q4 = q4_internal_force(X, u, *mat), eas = q4_eas_internal_force(X, u, *mat);
  EXPECT_LT((q4.internal_force - eas.internal_force).norm(), 1e-10 * q4.internal_force.norm());
}

// Pure bending of one rectangular element (u_x = kappa x y, u_y = -kappa x^2 / 2): the Q4
// locks (spurious shear), the enhanced element does not, so its bending stiffness is far lower.
TEST(Q4Eas, NoShearLockingInBending) {
  const auto mat = make_material("saint_venant_kirchhoff", ElasticConstants::from_youngs(1e3, 0.0));
  ElementCoords X;
  X << -1.0, -0.1, 1.0, -0.1, 1.0, 0.1, -1.0, 0.1;  // aspect ratio 10
  const double kappa = 1e-6;
  ElementVector u;
  for (int a = 0; a < 4; ++a) u.segment<2>(2 * a) << kappa * X(a, 0) * X(a, 1), 0.0;
  const double w_q4 = 0.5 * u.dot(q4_internal_force(X, u, *mat).internal_force);
  const double w_eas = 0.5 * u.dot(q4_eas_internal_force(X, u, *mat).internal_force);
  // Exact bending energy of the beam: E I kappa^2 L / 2 with I = h^3/12, L = 2, h = 0.2.
  const double exact = 0.5 * 1e3 * (0.2 * 0.2 * 0.2 / 12) * kappa * kappa * 2;
  EXPECT_NEAR(w_eas, exact, 1e-6 * exact);
  EXPECT_GT(w_q4, 20 * exact);
}

TEST(Q4, MassAndBodyForceIntegrateTheArea) {
  const ElementCoords X = distorted_quad();
  // Shoelace area of the quad.
  double area = 0;
  for (int a = 0; a < 4; ++a) area += 0.5 * (X(a, 0) * X((a + 1) % 4, 1) - X((a + 1) % 4, 0) * X(a, 1));
  const ElementMatrix M = q4_mass(X, 3.0);
  EXPECT_NEAR(M(Eigen::seq(0, 7, 2), Eigen::seq(0, 7, 2)).sum(), 3.0 * area, 1e-12);
  EXPECT_NEAR(M(Eigen::seq(0, 7, 2), Eigen::seq(1, 7, 2)).sum(), 0.0, 1e-15);
  const ElementVector f = q4_body_force(X, Eigen::Vector2d(0, -2));
  EXPECT_NEAR(f(Eigen::seq(1, 7, 2)).sum(), -2.0 * area, 1e-12);
}

TEST(EdgeMass, ConsistentLineMass) {
  const Eigen::Matrix4d M = edge_mass({0, 0}, {3, 4}, 2.0);  // length 5, weight 2
  EXPECT_NEAR(M(0, 0), 2.0 * 5 / 3, 1e-14);
  EXPECT_NEAR(M(0, 2), 2.0 * 5 / 6, 1e-14);
  EXPECT_NEAR(M.sum(), 2 * 2.0 * 5, 1e-13);  // int N^T N summed = length, per component
}

// Patch test: on a distorted mesh a displacement u = (F0 - I) X (uniform F0, hence
// uniform S) must (a) give zero internal force at every interior node and boundary
// forces equal to the traction P N integrated over the boundary, and (b) be reproduced
// exactly by Newton when the boundary displacements are prescribed.
TEST(PatchTest, UniformStressOnDistortedMesh) {
  SolidMesh mesh = rectangle_mesh(0, 0, 1, 1, 4, 4);
  distort_interior(mesh, 0.3);
  Matrix2 F0;
  F0 << 1.1, 0.05, 0.02, 0.95;
  const ElasticConstants c = ElasticConstants::from_shear(1.0, 0.3);
  auto mat = std::make_shared<NeoHookean>(c);
  const int n = mesh.num_nodes();
  Eigen::VectorXd exact(2 * n);
  for (int i = 0; i < n; ++i) exact.segment<2>(2 * i) = (F0 - Matrix2::Identity()) * mesh.nodes.row(i).transpose();

  std::vector<char> fixed(2 * n, 0);
  for (int node : mesh.facet_nodes({"left", "right", "bottom", "top"})) fixed[2 * node] = fixed[2 * node + 1] = 1;
  SolidSystem sys(mesh, mat, 1.0, fixed);
  const Eigen::VectorXd f = sys.internal_force(exact);
  // Boundary force: P = F S; on x = 1 face (N = e1, length 1), total = P e1.
  const auto k = Kinematics::from_deformation_gradient(F0);
  const Vector3 Sv = mat->stress(k);
  Matrix2 S;
  S << Sv(0), Sv(2), Sv(2), Sv(1);
  const Matrix2 P = F0 * S;
  Eigen::Vector2d right_total = Eigen::Vector2d::Zero();
  for (int node : mesh.facet_nodes({"right"})) right_total += f.segment<2>(2 * node);
  // Corner nodes are shared with top/bottom: subtract their half-edge share of those faces.
  for (int node : {4, 24}) right_total -= 0.5 * 0.25 * P * (node == 4 ? Eigen::Vector2d(0, -1) : Eigen::Vector2d(0, 1));
  EXPECT_LT((right_total - P.col(0)).norm(), 1e-12);
  for (int i = 0; i < n; ++i) {
    if (!fixed[2 * i]) {
      EXPECT_LT(f.segment<2>(2 * i).norm(), 1e-13) << "interior node " << i;
    }
  }

  // (b) Newton from zero interior displacement.
  Eigen::VectorXd d = Eigen::VectorXd::Zero(2 * n);
  for (int i = 0; i < 2 * n; ++i)
    if (fixed[i]) d(i) = exact(i);
  NewtonOptions opt;
  opt.residual_tolerance = 1e-13;
  const auto rep = sys.solve(d, Eigen::VectorXd::Zero(2 * n), TimeTerms{}, opt);
  EXPECT_TRUE(rep.converged);
  EXPECT_LT((d - exact).cwiseAbs().maxCoeff(), 1e-12);
  for (int cell = 0; cell < mesh.num_cells(); ++cell) {
    const Matrix2 F = q4_deformation_gradient(sys.cell_coordinates(cell), sys.cell_values(cell, d), 0.3, -0.6);
    EXPECT_LT((F - F0).norm(), 1e-12);
  }
}

// Manufactured solution, small strain (linear elastic limit of SVK): u = eps (phi, phi),
// phi = sin(pi x) sin(pi y) on the unit square, u = 0 on the boundary, body force
// b = -div sigma = eps [2 mu pi^2 phi + (lambda + mu) pi^2 (phi - cos(pi x) cos(pi y))] (1, 1).
// The L2 error of Q4 must converge at rate 2.
namespace {
double mms_error(int n) {
  const double eps = 1e-6, pi = M_PI;
  const ElasticConstants c = ElasticConstants::from_youngs(1.0, 0.3);
  SolidMesh mesh = rectangle_mesh(0, 0, 1, 1, n, n);
  std::vector<char> fixed(2 * mesh.num_nodes(), 0);
  for (int node : mesh.facet_nodes({"left", "right", "bottom", "top"})) fixed[2 * node] = fixed[2 * node + 1] = 1;
  SolidSystem sys(mesh, std::make_shared<SaintVenantKirchhoff>(c), 1.0, fixed);
  auto phi = [pi](const Eigen::Vector2d& x) { return std::sin(pi * x(0)) * std::sin(pi * x(1)); };
  const Eigen::VectorXd f = sys.body_force([&](const Eigen::Vector2d& x) {
    const double cc = std::cos(pi * x(0)) * std::cos(pi * x(1));
    const double b = eps * (2 * c.mu * pi * pi * phi(x) + (c.lambda + c.mu) * pi * pi * (phi(x) - cc));
    return Eigen::Vector2d(b, b);
  });
  Eigen::VectorXd d = Eigen::VectorXd::Zero(sys.num_dofs());
  NewtonOptions opt;
  opt.residual_tolerance = 1e-12;
  EXPECT_TRUE(sys.solve(d, f, TimeTerms{}, opt).converged);
  double err2 = 0, norm2 = 0;
  const auto rule = gauss_rule_2d(3);
  for (int cell = 0; cell < mesh.num_cells(); ++cell) {
    const auto X = sys.cell_coordinates(cell);
    const auto u = sys.cell_values(cell, d);
    for (const auto& [xi, eta, w] : rule) {
      const Eigen::Vector4d N = q4_shape(xi, eta);
      const double dV = w * (X.transpose() * q4_shape_derivatives(xi, eta)).determinant();
      const Eigen::Vector2d x = X.transpose() * N;
      Eigen::Vector2d uh = Eigen::Vector2d::Zero();
      for (int a = 0; a < 4; ++a) uh += N(a) * u.segment<2>(2 * a);
      const Eigen::Vector2d ue = Eigen::Vector2d::Constant(eps * phi(x));
      err2 += dV * (uh - ue).squaredNorm();
      norm2 += dV * ue.squaredNorm();
    }
  }
  return std::sqrt(err2 / norm2);
}
}  // namespace

TEST(ManufacturedSolution, L2ConvergenceRateTwo) {
  const double e8 = mms_error(8), e16 = mms_error(16), e32 = mms_error(32);
  const double r1 = std::log2(e8 / e16), r2 = std::log2(e16 / e32);
  std::printf("MMS relative L2 errors: h=1/8 %.4e, 1/16 %.4e, 1/32 %.4e; rates %.3f, %.3f\n", e8, e16, e32, r1, r2);
  EXPECT_NEAR(r2, 2.0, 0.1);
  EXPECT_LT(e32, 5e-3);
}

TEST(SolidSystem, InvertedElementIsReported) {
  SolidMesh mesh = rectangle_mesh(0, 0, 1, 1, 2, 1);
  SolidSystem sys(mesh, std::make_shared<SaintVenantKirchhoff>(ElasticConstants::from_shear(1, 0.3)), 1.0,
                  std::vector<char>(2 * mesh.num_nodes(), 0));
  Eigen::VectorXd d = Eigen::VectorXd::Zero(sys.num_dofs());
  d(2 * 1) = -2.0;  // node 1 pushed through its neighbour: element 0 inverts
  try {
    sys.internal_force(d);
    FAIL() << "expected InvertedElement";
  } catch (const InvertedElement& e) {
    EXPECT_EQ(e.element, 0);
    EXPECT_LT(e.det_F, 0);
  }
}

// CHOLMOD is tried first; an indefinite matrix makes the solver switch to UMFPACK.
TEST(SparseDirectSolver, FallsBackToUmfpackOnIndefiniteMatrix) {
  SparseMatrix A(3, 3);
  A.insert(0, 0) = 2;
  A.insert(1, 1) = -1;
  A.insert(2, 2) = 3;
  A.insert(0, 2) = 1;
  A.insert(2, 0) = 1;
  A.makeCompressed();
  SparseDirectSolver solver(LinearSolverKind::Cholmod);
  solver.factorize(A);
  EXPECT_EQ(solver.kind(), LinearSolverKind::Umfpack);
  const Eigen::Vector3d b(1, 2, 3);
  EXPECT_LT((A * solver.solve(b) - b).norm(), 1e-12);
  // SPD stays with CHOLMOD, and refactorising the same pattern works.
  A.coeffRef(1, 1) = 4;
  SparseDirectSolver spd(LinearSolverKind::Cholmod);
  spd.factorize(A);
  A.coeffRef(1, 1) = 5;
  spd.factorize(A);
  EXPECT_EQ(spd.kind(), LinearSolverKind::Cholmod);
  EXPECT_LT((A * spd.solve(b) - b).norm(), 1e-12);
}
