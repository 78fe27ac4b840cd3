// Kinematics and material laws against hand-computed values and finite differences.
#include <gtest/gtest.h>

#include <cmath>

#include "fsi/solid/material.hpp"

using namespace fsi::solid;

namespace {
Matrix2 sample_F() {
  Matrix2 F;
  F << 1.1, 0.2, 0.05, 0.9;
  return F;
}
}  // namespace

TEST(Kinematics, HandComputedFCEJ) {
  const auto k = Kinematics::from_deformation_gradient(sample_F());
  // C = F^T F: C11 = 1.1^2 + 0.05^2, C12 = 1.1*0.2 + 0.05*0.9, C22 = 0.2^2 + 0.9^2.
  EXPECT_NEAR(k.C(0, 0), 1.2125, 1e-12);
  EXPECT_NEAR(k.C(0, 1), 0.265, 1e-12);
  EXPECT_NEAR(k.C(1, 0), 0.265, 1e-12);
  EXPECT_NEAR(k.C(1, 1), 0.85, 1e-12);
  EXPECT_NEAR(k.E(0, 0), 0.10625, 1e-12);
  EXPECT_NEAR(k.E(0, 1), 0.1325, 1e-12);
  EXPECT_NEAR(k.E(1, 1), -0.075, 1e-12);
  EXPECT_NEAR(k.J, 0.98, 1e-12);  // 1.1*0.9 - 0.2*0.05
}

TEST(ElasticConstants, FromYoungsAndShear) {
  const auto a = ElasticConstants::from_shear(0.5e6, 0.4);
  EXPECT_NEAR(a.lambda, 2.0e6, 1e-6);  // Turek-Hron: lambda = 4 mu for nu = 0.4
  const auto b = ElasticConstants::from_youngs(200.0, 0.3);
  EXPECT_NEAR(b.mu, 200.0 / 2.6, 1e-12);
  EXPECT_NEAR(b.lambda, 200.0 * 0.3 / (1.3 * 0.4), 1e-12);
}

TEST(SaintVenantKirchhoff, HandComputedStress) {
  SaintVenantKirchhoff svk({1.0, 2.0});  // mu = 1, lambda = 2
  const auto S = svk.stress(Kinematics::from_deformation_gradient(sample_F()));
  // tr E = 0.03125; S = 2 * 0.03125 I + 2 E.
  EXPECT_NEAR(S(0), 0.0625 + 0.2125, 1e-12);
  EXPECT_NEAR(S(1), 0.0625 - 0.15, 1e-12);
  EXPECT_NEAR(S(2), 0.265, 1e-12);
}

TEST(NeoHookean, HandComputedStress) {
  NeoHookean nh({1.0, 2.0});
  const auto S = nh.stress(Kinematics::from_deformation_gradient(sample_F()));
  // det C = J^2 = 0.9604; C^-1 = [[0.85, -0.265], [-0.265, 1.2125]] / 0.9604.
  const double l = std::log(0.98), d = 0.9604;
  EXPECT_NEAR(S(0), 1.0 - 0.85 / d + 2 * l * 0.85 / d, 1e-12);
  EXPECT_NEAR(S(1), 1.0 - 1.2125 / d + 2 * l * 1.2125 / d, 1e-12);
  EXPECT_NEAR(S(2), 0.265 / d - 2 * l * 0.265 / d, 1e-12);
  // Stress free at F = I.
  const auto S0 = nh.stress(Kinematics::from_deformation_gradient(Matrix2::Identity()));
  EXPECT_LT(S0.norm(), 1e-15);
}

TEST(NeoHookean, SmallStrainLimitMatchesSaintVenantKirchhoff) {
  const ElasticConstants c = ElasticConstants::from_youngs(1e3, 0.3);
  NeoHookean nh(c);
  SaintVenantKirchhoff svk(c);
  const auto k = Kinematics::from_deformation_gradient(Matrix2::Identity());
  EXPECT_LT((nh.tangent(k) - svk.tangent(k)).norm(), 1e-9 * svk.tangent(k).norm());
}

class MaterialTangent : public ::testing::TestWithParam<std::string> {};

// D = dS/dE against central differences of S(F) along random directions dF:
// dE = sym(F^T dF), Voigt with engineering shear.
TEST_P(MaterialTangent, MatchesFiniteDifferences) {
  const auto mat = make_material(GetParam(), ElasticConstants::from_shear(0.5e6, 0.4));
  const Matrix2 F = sample_F();
  const auto k = Kinematics::from_deformation_gradient(F);
  const Matrix3 D = mat->tangent(k);
  EXPECT_LT((D - D.transpose()).norm(), 1e-10 * D.norm());
  std::srand(7);
  for (int trial = 0; trial < 5; ++trial) {
    const Matrix2 dF = Matrix2::Random();
    const double h = 1e-6;
    const Vector3 fd = (mat->stress(Kinematics::from_deformation_gradient(F + h * dF)) -
                        mat->stress(Kinematics::from_deformation_gradient(F - h * dF))) /
                       (2 * h);
    const Matrix2 dE = 0.5 * (F.transpose() * dF + dF.transpose() * F);
    const Vector3 predicted = D * Vector3(dE(0, 0), dE(1, 1), 2 * dE(0, 1));
    EXPECT_LT((fd - predicted).norm(), 1e-7 * predicted.norm()) << GetParam() << " trial " << trial;
  }
}

// S = dW/dE: the stress is the derivative of the energy.
TEST_P(MaterialTangent, StressIsEnergyDerivative) {
  const auto mat = make_material(GetParam(), ElasticConstants::from_shear(1.0, 0.3));
  const Matrix2 F = sample_F();
  const auto k = Kinematics::from_deformation_gradient(F);
  const Vector3 S = mat->stress(k);
  const Matrix2 dF = Matrix2::Random();
  const double h = 1e-6;
  const double dW = (mat->energy(Kinematics::from_deformation_gradient(F + h * dF)) -
                     mat->energy(Kinematics::from_deformation_gradient(F - h * dF))) /
                    (2 * h);
  const Matrix2 dE = 0.5 * (F.transpose() * dF + dF.transpose() * F);
  EXPECT_NEAR(dW, S(0) * dE(0, 0) + S(1) * dE(1, 1) + 2 * S(2) * dE(0, 1), 1e-8);
}

INSTANTIATE_TEST_SUITE_P(Laws, MaterialTangent, ::testing::Values("saint_venant_kirchhoff", "neo_hookean"));

TEST(Material, UnknownLawIsAnError) { EXPECT_THROW(make_material("mooney", {1, 1}), std::invalid_argument); }
