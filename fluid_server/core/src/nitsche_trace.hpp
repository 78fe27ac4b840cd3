#pragma once
// The Nitsche terms of one quadrature point on an interface edge (2D) or face (3D), shared by
// the Taylor-Hood elements of both dimensions (flow_element_p2p1.cpp, flow_element_p2p1_tet.cpp).
// Private to fsi_fluid.
//
// The seed paper's fluid weak form on the interface Gamma (v_s the solid's velocity):
//   gamma_N1 int w . (v - v_s) - mu int w . (grad v) n - g2 mu int (grad w) n . (v - v_s)
//   + int w . n p + g2 int q n . (v - v_s)
// with g2 = fluid.nitsche.symmetry (1 symmetric, -1 skew).
#include <Eigen/Core>

#include "flow_element.hpp"

namespace fsi::fluid::detail {

// The geometry at a point of an element's edge (Dim 2) or face (Dim 3): the element's NN
// shape functions and physical gradients, the measure (length or area) element, the outward
// unit normal and the linear (pressure) shape functions of the vertices.
template <int NN, int Dim>
struct TracePoint {
  Eigen::Matrix<double, NN, 1> N;
  Eigen::Matrix<double, NN, Dim> G;
  double ds = 0;
  Eigen::Matrix<double, Dim, 1> normal;
  Eigen::Matrix<double, Dim + 1, 1> L;
};

// Adds the point's terms (weight w; w_pen that of the penalty term, which may sit on the
// step-start geometry) to the local system: velocity (Dim per node, interleaved) first, then
// the Dim + 1 vertex pressures. vs: the solid velocity at the element's nodes (0 off the interface).
template <int NN, int Dim>
void add_nitsche_point(const TracePoint<NN, Dim>& p, double w, double w_pen, const Eigen::Matrix<double, NN, Dim>& vs,
                       const FlowParameters& params, LocalSystem& out) {
  constexpr int P = Dim * NN;  // the first pressure unknown
  const double g1 = params.nitsche_penalty, g2 = params.nitsche_symmetry, mu = params.viscosity;
  const bool step_start = params.penalty_on_step_start;
  const Eigen::Matrix<double, NN, 1> gn = p.G * p.normal;
  const Eigen::Matrix<double, 1, Dim> v = p.N.transpose() * vs;
  for (int i = 0; i < NN; ++i) {
    for (int j = 0; j < NN; ++j) {
      // (the default's arithmetic exactly as before the penalty_geometry option)
      const double vel = step_start
                             ? w_pen * g1 * p.N(i) * p.N(j) + w * (-mu * p.N(i) * gn(j) - g2 * mu * gn(i) * p.N(j))
                             : w * (g1 * p.N(i) * p.N(j) - mu * p.N(i) * gn(j) - g2 * mu * gn(i) * p.N(j));
      for (int c = 0; c < Dim; ++c) out.matrix(Dim * i + c, Dim * j + c) += vel;
    }
    for (int j = 0; j < Dim + 1; ++j)
      for (int c = 0; c < Dim; ++c) {
        out.matrix(Dim * i + c, P + j) += w * p.N(i) * p.normal(c) * p.L(j);
        out.matrix(P + j, Dim * i + c) += w * g2 * p.L(j) * p.normal(c) * p.N(i);
      }
    for (int c = 0; c < Dim; ++c)
      out.rhs(Dim * i + c) +=
          step_start ? (w_pen * g1 * p.N(i) - w * g2 * mu * gn(i)) * v(c) : w * (g1 * p.N(i) - g2 * mu * gn(i)) * v(c);
  }
  for (int j = 0; j < Dim + 1; ++j) out.rhs(P + j) += w * g2 * p.L(j) * v.dot(p.normal.transpose());
}

}  // namespace fsi::fluid::detail
