#include "fsi/solid/material.hpp"

#include <cmath>
#include <stdexcept>

namespace fsi::solid {

namespace {
// Voigt index pairs: [11, 22, 12] in 2D, [11, 22, 33, 12, 23, 13] in 3D.
template <int dim>
struct VoigtPairs;
template <>
struct VoigtPairs<2> {
  static constexpr int I[3] = {0, 1, 0};
  static constexpr int J[3] = {0, 1, 1};
};
template <>
struct VoigtPairs<3> {
  static constexpr int I[6] = {0, 1, 2, 0, 1, 0};
  static constexpr int J[6] = {0, 1, 2, 1, 2, 2};
};

template <int dim>
Eigen::Matrix<double, voigt_size<dim>, 1> voigt(const Eigen::Matrix<double, dim, dim>& A) {
  Eigen::Matrix<double, voigt_size<dim>, 1> v;
  for (int a = 0; a < voigt_size<dim>; ++a) v(a) = A(VoigtPairs<dim>::I[a], VoigtPairs<dim>::J[a]);
  return v;
}

// Sum of the principal 2x2 minors of a 3x3 matrix (its second invariant).
double second_invariant(const Eigen::Matrix3d& A) {
  return (A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0)) + (A(1, 1) * A(2, 2) - A(1, 2) * A(2, 1)) +
         (A(0, 0) * A(2, 2) - A(0, 2) * A(2, 0));
}
}  // namespace

template <int dim>
Eigen::Matrix<double, dim, dim> from_voigt(const Eigen::Matrix<double, voigt_size<dim>, 1>& s) {
  Eigen::Matrix<double, dim, dim> A;
  for (int a = 0; a < voigt_size<dim>; ++a)
    A(VoigtPairs<dim>::I[a], VoigtPairs<dim>::J[a]) = A(VoigtPairs<dim>::J[a], VoigtPairs<dim>::I[a]) = s(a);
  return A;
}

template <int dim>
KinematicsT<dim> KinematicsT<dim>::from_deformation_gradient(const Tensor& F) {
  return from_displacement_gradient(F - Tensor::Identity());
}

template <int dim>
KinematicsT<dim> KinematicsT<dim>::from_green_lagrange(const Tensor& E, const Tensor& F) {
  KinematicsT k;
  k.F = F;
  k.E = 0.5 * (E + E.transpose());
  k.C = Tensor::Identity() + 2.0 * k.E;
  double det_c_minus_1;  // det(I + 2 E) - 1 from the invariants of E
  if constexpr (dim == 2)
    det_c_minus_1 = 2.0 * k.E.trace() + 4.0 * k.E.determinant();
  else
    det_c_minus_1 = 2.0 * k.E.trace() + 4.0 * second_invariant(k.E) + 8.0 * k.E.determinant();
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

template <int dim>
KinematicsT<dim> KinematicsT<dim>::from_displacement_gradient(const Tensor& H) {
  KinematicsT k;
  k.F = Tensor::Identity() + H;
  k.E = 0.5 * (H + H.transpose() + H.transpose() * H);
  k.C = Tensor::Identity() + 2.0 * k.E;
  if constexpr (dim == 2)
    k.J_minus_1 = H.trace() + H.determinant();
  else
    k.J_minus_1 = H.trace() + second_invariant(H) + H.determinant();
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

template <int dim>
auto SaintVenantKirchhoffT<dim>::stress(const KinematicsT<dim>& k) const -> Stress {
  using Tensor = typename KinematicsT<dim>::Tensor;
  const Tensor S = c_.lambda * k.E.trace() * Tensor::Identity() + 2.0 * c_.mu * k.E;
  return voigt<dim>(S);
}

template <int dim>
auto SaintVenantKirchhoffT<dim>::tangent(const KinematicsT<dim>&) const -> Tangent {
  Tangent D = Tangent::Zero();
  const double l = c_.lambda, m = c_.mu;
  for (int a = 0; a < dim; ++a) {
    for (int b = 0; b < dim; ++b) D(a, b) = l;
    D(a, a) = l + 2 * m;
  }
  for (int a = dim; a < voigt_size<dim>; ++a) D(a, a) = m;
  return D;
}

template <int dim>
double SaintVenantKirchhoffT<dim>::energy(const KinematicsT<dim>& k) const {
  const double tr = k.E.trace();
  return 0.5 * c_.lambda * tr * tr + c_.mu * (k.E.array() * k.E.array()).sum();
}

template <int dim>
auto NeoHookeanT<dim>::stress(const KinematicsT<dim>& k) const -> Stress {
  using Tensor = typename KinematicsT<dim>::Tensor;
  const Tensor Ci = k.C.inverse();
  // mu (I - C^-1) = 2 mu C^-1 E, written so that small strains lose no digits.
  const Tensor S = 2.0 * c_.mu * Ci * k.E + c_.lambda * std::log1p(k.J_minus_1) * Ci;
  return voigt<dim>(S);
}

template <int dim>
auto NeoHookeanT<dim>::tangent(const KinematicsT<dim>& k) const -> Tangent {
  using Tensor = typename KinematicsT<dim>::Tensor;
  const Tensor Ci = k.C.inverse();
  const double lnJ = std::log1p(k.J_minus_1);
  const double mu_eff = c_.mu - c_.lambda * lnJ;
  Tangent D;
  for (int a = 0; a < voigt_size<dim>; ++a)
    for (int b = 0; b < voigt_size<dim>; ++b) {
      const int I = VoigtPairs<dim>::I[a], J = VoigtPairs<dim>::J[a], K = VoigtPairs<dim>::I[b],
                L = VoigtPairs<dim>::J[b];
      D(a, b) = c_.lambda * Ci(I, J) * Ci(K, L) + mu_eff * (Ci(I, K) * Ci(J, L) + Ci(I, L) * Ci(J, K));
    }
  return D;
}

template <int dim>
double NeoHookeanT<dim>::energy(const KinematicsT<dim>& k) const {
  const double lnJ = std::log1p(k.J_minus_1);
  // Plane strain: C33 = 1 adds to tr C.
  const double tr_C = dim == 2 ? k.C.trace() + 1.0 : k.C.trace();
  return 0.5 * c_.mu * (tr_C - 3.0) - c_.mu * lnJ + 0.5 * c_.lambda * lnJ * lnJ;
}

template <int dim>
Eigen::Matrix<double, voigt_size<dim>, 1> cauchy_stress(const KinematicsT<dim>& k,
                                                        const Eigen::Matrix<double, voigt_size<dim>, 1>& S) {
  const Eigen::Matrix<double, dim, dim> Sm = from_voigt<dim>(S);
  return voigt<dim>(Eigen::Matrix<double, dim, dim>(k.F * Sm * k.F.transpose() / k.J));
}

template <int dim>
std::unique_ptr<MaterialLaw<dim>> make_material(const std::string& law, ElasticConstants c) {
  if (law == "saint_venant_kirchhoff" || law == "svk") return std::make_unique<SaintVenantKirchhoffT<dim>>(c);
  if (law == "neo_hookean") return std::make_unique<NeoHookeanT<dim>>(c);
  throw std::invalid_argument("unknown material law '" + law + "' (known: saint_venant_kirchhoff, neo_hookean)");
}

std::unique_ptr<Material> make_material(const std::string& law, ElasticConstants c) { return make_material<2>(law, c); }

#define FSI_SOLID_INSTANTIATE(dim)                                                                            \
  template struct KinematicsT<dim>;                                                                           \
  template class SaintVenantKirchhoffT<dim>;                                                                  \
  template class NeoHookeanT<dim>;                                                                            \
  template Eigen::Matrix<double, dim, dim> from_voigt<dim>(const Eigen::Matrix<double, voigt_size<dim>, 1>&); \
  template Eigen::Matrix<double, voigt_size<dim>, 1> cauchy_stress<dim>(                                      \
      const KinematicsT<dim>&, const Eigen::Matrix<double, voigt_size<dim>, 1>&);                             \
  template std::unique_ptr<MaterialLaw<dim>> make_material<dim>(const std::string&, ElasticConstants);
FSI_SOLID_INSTANTIATE(2)
FSI_SOLID_INSTANTIATE(3)
#undef FSI_SOLID_INSTANTIATE

}  // namespace fsi::solid
