#pragma once
// Hyperelastic material laws, total Lagrangian, in 2D plane strain and in 3D: one code for
// both, templated on the dimension (dim = 2 or 3).
//
// Conventions (dim x dim):
//   F = I + Grad u,  C = F^T F,  E = (C - I)/2,  J = det F.  In 2D (plane strain) the
//   out-of-plane stretch is 1: F33 = 1, E33 = 0.
//   S: second Piola-Kirchhoff stress.  Voigt order [11, 22, 12] in 2D and
//   [11, 22, 33, 12, 23, 13] in 3D for stresses; strains with doubled shears
//   ([E11, E22, 2 E12], ...), so dS_voigt = D dE_voigt with D = dS/dE (symmetric).
// Kernels take and return Eigen types; no I/O.
#include <Eigen/Core>
#include <Eigen/LU>
#include <memory>
#include <string>

namespace fsi::solid {

using Matrix2 = Eigen::Matrix2d;
using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

// Number of independent components of a symmetric dim x dim tensor (3 in 2D, 6 in 3D).
template <int dim>
inline constexpr int voigt_size = dim*(dim + 1) / 2;

template <int dim>
struct KinematicsT {
  using Tensor = Eigen::Matrix<double, dim, dim>;
  Tensor F, C, E;
  double J = 1;
  double J_minus_1 = 0;  // J - 1 without cancellation (invariants of H)
  static KinematicsT from_deformation_gradient(const Tensor& F);
  // From H = Grad u: E = (H + H^T + H^T H)/2 and J - 1 = det(I + H) - 1 from the invariants
  // of H, without the cancellation of F^T F - I, so that tiny strains (1e-10) keep full
  // relative accuracy.
  static KinematicsT from_displacement_gradient(const Tensor& H);
  // From a Green-Lagrange strain that need not be compatible (enhanced assumed strain):
  // C = I + 2 E, J = sqrt(det C), J - 1 without cancellation; F is left as given (the
  // compatible one: the materials use E, C and J only).
  static KinematicsT from_green_lagrange(const Tensor& E, const Tensor& F);
};
using Kinematics = KinematicsT<2>;
using Kinematics3 = KinematicsT<3>;

// Lame parameters from either (E, nu) or (mu, nu); the same in plane strain and 3D.
struct ElasticConstants {
  double mu = 0, lambda = 0;
  static ElasticConstants from_youngs(double youngs_modulus, double poisson_ratio);
  static ElasticConstants from_shear(double shear_modulus, double poisson_ratio);
};

// A hyperelastic law: energy, stress and tangent (MFEM's three-method interface).
template <int dim>
class MaterialLaw {
 public:
  using Stress = Eigen::Matrix<double, voigt_size<dim>, 1>;
  using Tangent = Eigen::Matrix<double, voigt_size<dim>, voigt_size<dim>>;
  virtual ~MaterialLaw() = default;
  virtual std::string name() const = 0;
  // Second Piola-Kirchhoff stress S (Voigt).
  virtual Stress stress(const KinematicsT<dim>& k) const = 0;
  // Material tangent D = dS/dE in Voigt form (symmetric).
  virtual Tangent tangent(const KinematicsT<dim>& k) const = 0;
  // Strain energy per unit reference volume.
  virtual double energy(const KinematicsT<dim>& k) const = 0;
};
using Material = MaterialLaw<2>;
using Material3 = MaterialLaw<3>;

// S = lambda tr(E) I + 2 mu E.
template <int dim>
class SaintVenantKirchhoffT final : public MaterialLaw<dim> {
 public:
  using typename MaterialLaw<dim>::Stress;
  using typename MaterialLaw<dim>::Tangent;
  explicit SaintVenantKirchhoffT(ElasticConstants c) : c_(c) {}
  std::string name() const override { return "saint_venant_kirchhoff"; }
  Stress stress(const KinematicsT<dim>& k) const override;
  Tangent tangent(const KinematicsT<dim>& k) const override;
  double energy(const KinematicsT<dim>& k) const override;

 private:
  ElasticConstants c_;
};
using SaintVenantKirchhoff = SaintVenantKirchhoffT<2>;

// Compressible Neo-Hookean of Bonet & Wood (2008, eq. 6.27-6.28):
//   W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2,
//   S = mu (I - C^-1) + lambda ln J C^-1,
//   dS/dE = lambda C^-1 (x) C^-1 + 2 (mu - lambda ln J) I_{C^-1},
//   I_{C^-1}_IJKL = (C^-1_IK C^-1_JL + C^-1_IL C^-1_JK)/2.
// Plane strain: tr C = C11 + C22 + 1 and J = det of the 2x2 F.
template <int dim>
class NeoHookeanT final : public MaterialLaw<dim> {
 public:
  using typename MaterialLaw<dim>::Stress;
  using typename MaterialLaw<dim>::Tangent;
  explicit NeoHookeanT(ElasticConstants c) : c_(c) {}
  std::string name() const override { return "neo_hookean"; }
  Stress stress(const KinematicsT<dim>& k) const override;
  Tangent tangent(const KinematicsT<dim>& k) const override;
  double energy(const KinematicsT<dim>& k) const override;

 private:
  ElasticConstants c_;
};
using NeoHookean = NeoHookeanT<2>;

// Cauchy stress sigma = F S F^T / J (Voigt).
template <int dim>
Eigen::Matrix<double, voigt_size<dim>, 1> cauchy_stress(const KinematicsT<dim>& k,
                                                        const Eigen::Matrix<double, voigt_size<dim>, 1>& S);
inline Vector3 cauchy_stress(const Kinematics& k, const Vector3& S) { return cauchy_stress<2>(k, S); }

// The symmetric tensor of Voigt components s (stress order, no doubled shears).
template <int dim>
Eigen::Matrix<double, dim, dim> from_voigt(const Eigen::Matrix<double, voigt_size<dim>, 1>& s);

// Builds a law by name ("saint_venant_kirchhoff" / "svk", "neo_hookean"); throws
// std::invalid_argument for an unknown name. make_material(...) is the 2D law.
template <int dim>
std::unique_ptr<MaterialLaw<dim>> make_material(const std::string& law, ElasticConstants c);
std::unique_ptr<Material> make_material(const std::string& law, ElasticConstants c);

}  // namespace fsi::solid
