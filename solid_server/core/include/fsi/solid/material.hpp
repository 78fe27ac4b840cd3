#pragma once
// Hyperelastic material laws for 2D plane strain, total Lagrangian.
//
// Conventions (all 2x2, the out-of-plane stretch is 1: F33 = 1, E33 = 0):
//   F = I + Grad u,  C = F^T F,  E = (C - I)/2,  J = det F.
//   S: second Piola-Kirchhoff stress.  Voigt order [11, 22, 12] for stresses and
//   [E11, E22, 2 E12] for strains, so dS_voigt = D dE_voigt with D = dS/dE (symmetric).
// Kernels take and return Eigen types; no I/O.
#include <Eigen/Core>
#include <Eigen/LU>
#include <memory>
#include <string>

namespace fsi::solid {

using Matrix2 = Eigen::Matrix2d;
using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;

struct Kinematics {
  Matrix2 F, C, E;
  double J = 1;
  double J_minus_1 = 0;  // J - 1 without cancellation (tr H + det H)
  static Kinematics from_deformation_gradient(const Matrix2& F);
  // From H = Grad u: E = (H + H^T + H^T H)/2 and J - 1 computed without the cancellation
  // of F^T F - I, so that tiny strains (1e-10) keep full relative accuracy.
  static Kinematics from_displacement_gradient(const Matrix2& H);
  // From a Green-Lagrange strain that need not be compatible (enhanced assumed strain):
  // C = I + 2 E, J = sqrt(det C), J - 1 without cancellation; F is left as given (the
  // compatible one: the materials use E, C and J only).
  static Kinematics from_green_lagrange(const Matrix2& E, const Matrix2& F);
};

// Lame parameters for plane strain from either (E, nu) or (mu, nu).
struct ElasticConstants {
  double mu = 0, lambda = 0;
  static ElasticConstants from_youngs(double youngs_modulus, double poisson_ratio);
  static ElasticConstants from_shear(double shear_modulus, double poisson_ratio);
};

class Material {
 public:
  virtual ~Material() = default;
  virtual std::string name() const = 0;
  // Second Piola-Kirchhoff stress S (Voigt [S11, S22, S12]).
  virtual Vector3 stress(const Kinematics& k) const = 0;
  // Material tangent D = dS/dE in Voigt form (3x3, symmetric).
  virtual Matrix3 tangent(const Kinematics& k) const = 0;
  // Strain energy per unit reference volume.
  virtual double energy(const Kinematics& k) const = 0;
};

// S = lambda tr(E) I + 2 mu E.
class SaintVenantKirchhoff final : public Material {
 public:
  explicit SaintVenantKirchhoff(ElasticConstants c) : c_(c) {}
  std::string name() const override { return "saint_venant_kirchhoff"; }
  Vector3 stress(const Kinematics& k) const override;
  Matrix3 tangent(const Kinematics& k) const override;
  double energy(const Kinematics& k) const override;

 private:
  ElasticConstants c_;
};

// Compressible Neo-Hookean of Bonet & Wood (2008, eq. 6.27-6.28):
//   W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2,
//   S = mu (I - C^-1) + lambda ln J C^-1,
//   dS/dE = lambda C^-1 (x) C^-1 + 2 (mu - lambda ln J) I_{C^-1},
//   I_{C^-1}_IJKL = (C^-1_IK C^-1_JL + C^-1_IL C^-1_JK)/2.
// Plane strain: tr C = C11 + C22 + 1 and J = det of the 2x2 F.
class NeoHookean final : public Material {
 public:
  explicit NeoHookean(ElasticConstants c) : c_(c) {}
  std::string name() const override { return "neo_hookean"; }
  Vector3 stress(const Kinematics& k) const override;
  Matrix3 tangent(const Kinematics& k) const override;
  double energy(const Kinematics& k) const override;

 private:
  ElasticConstants c_;
};

// Cauchy stress sigma = F S F^T / J (Voigt [xx, yy, xy]).
Vector3 cauchy_stress(const Kinematics& k, const Vector3& S);

// Builds a law by name ("saint_venant_kirchhoff" / "svk", "neo_hookean"); throws
// std::invalid_argument for an unknown name.
std::unique_ptr<Material> make_material(const std::string& law, ElasticConstants c);

}  // namespace fsi::solid
