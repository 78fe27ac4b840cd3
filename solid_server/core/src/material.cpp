#include "fsi/solid/material.hpp"

#include <cmath>
#include <stdexcept>

namespace fsi::solid {

Kinematics Kinematics::from_deformation_gradient(const Matrix2& F) {
  return from_displacement_gradient(F - Matrix2::Identity());
}

Kinematics Kinematics::from_green_lagrange(const Matrix2& E, const Matrix2& F) {
  Kinematics k;
  k.F = F;
  k.E = 0.5 * (E + E.transpose());
  k.C = Matrix2::Identity() + 2.0 * k.E;
  const double det_c_minus_1 = 2.0 * k.E.trace() + 4.0 * k.E.determinant();
  const double det_c = 1.0 + det_c_minus_1;
  if (!(det_c > 0)) {
    k.J = -1;  // not a deformation: reported as inverted by the element
    k.J_minus_1 = -2;
    return k;
  }
  k.J = std::sqrt(det_c);
  k.J_minus_1 = det_c_minus_1 / (k.J + 1.0);
  return k;
}

Kinematics Kinematics::from_displacement_gradient(const Matrix2& H) {
  Kinematics k;
  k.F = Matrix2::Identity() + H;
  k.E = 0.5 * (H + H.transpose() + H.transpose() * H);
  k.C = Matrix2::Identity() + 2.0 * k.E;
  k.J_minus_1 = H.trace() + H.determinant();
  k.J = 1.0 + k.J_minus_1;
  return k;
}

ElasticConstants ElasticConstants::from_youngs(double E, double nu) {
  ElasticConstants c;
  c.mu = E / (2.0 * (1.0 + nu));
  c.lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  return c;
}

ElasticConstants ElasticConstants::from_shear(double mu, double nu) {
  ElasticConstants c;
  c.mu = mu;
  c.lambda = 2.0 * mu * nu / (1.0 - 2.0 * nu);
  return c;
}

namespace {
Vector3 voigt(const Matrix2& A) { return {A(0, 0), A(1, 1), A(0, 1)}; }

// Voigt index pairs [11, 22, 12].
constexpr int kI[3] = {0, 1, 0};
constexpr int kJ[3] = {0, 1, 1};
}  // namespace

Vector3 SaintVenantKirchhoff::stress(const Kinematics& k) const {
  const Matrix2 S = c_.lambda * k.E.trace() * Matrix2::Identity() + 2.0 * c_.mu * k.E;
  return voigt(S);
}

Matrix3 SaintVenantKirchhoff::tangent(const Kinematics&) const {
  Matrix3 D;
  const double l = c_.lambda, m = c_.mu;
  D << l + 2 * m, l, 0,  //
      l, l + 2 * m, 0,   //
      0, 0, m;
  return D;
}

double SaintVenantKirchhoff::energy(const Kinematics& k) const {
  const double tr = k.E.trace();
  return 0.5 * c_.lambda * tr * tr + c_.mu * (k.E.array() * k.E.array()).sum();
}

Vector3 NeoHookean::stress(const Kinematics& k) const {
  const Matrix2 Ci = k.C.inverse();
  // mu (I - C^-1) = 2 mu C^-1 E, written so that small strains lose no digits.
  const Matrix2 S = 2.0 * c_.mu * Ci * k.E + c_.lambda * std::log1p(k.J_minus_1) * Ci;
  return voigt(S);
}

Matrix3 NeoHookean::tangent(const Kinematics& k) const {
  const Matrix2 Ci = k.C.inverse();
  const double lnJ = std::log1p(k.J_minus_1);
  const double mu_eff = c_.mu - c_.lambda * lnJ;
  Matrix3 D;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const int I = kI[a], J = kJ[a], K = kI[b], L = kJ[b];
      D(a, b) = c_.lambda * Ci(I, J) * Ci(K, L) + mu_eff * (Ci(I, K) * Ci(J, L) + Ci(I, L) * Ci(J, K));
    }
  return D;
}

double NeoHookean::energy(const Kinematics& k) const {
  const double lnJ = std::log1p(k.J_minus_1);
  return 0.5 * c_.mu * (k.C.trace() + 1.0 - 3.0) - c_.mu * lnJ + 0.5 * c_.lambda * lnJ * lnJ;
}

Vector3 cauchy_stress(const Kinematics& k, const Vector3& S) {
  Matrix2 Sm;
  Sm << S(0), S(2), S(2), S(1);
  return voigt(k.F * Sm * k.F.transpose() / k.J);
}

std::unique_ptr<Material> make_material(const std::string& law, ElasticConstants c) {
  if (law == "saint_venant_kirchhoff" || law == "svk") return std::make_unique<SaintVenantKirchhoff>(c);
  if (law == "neo_hookean") return std::make_unique<NeoHookean>(c);
  throw std::invalid_argument("unknown material law '" + law + "' (known: saint_venant_kirchhoff, neo_hookean)");
}

}  // namespace fsi::solid
