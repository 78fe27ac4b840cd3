// The `coupling` section's keys, declared once beside their reader (settings.cpp): names,
// defaults, units, ranges and meanings. `fsi check` and docs/scene-reference.md come from here.
#include "fsi/common/scene_schema.hpp"
#include "fsi/coupling/acceleration.hpp"
#include "fsi/coupling/predictor.hpp"
#include "fsi/coupling/settings.hpp"

namespace fsi::coupling {
namespace {

template <typename Schemes>
std::vector<std::string> names_of(const Schemes& schemes) {
  std::vector<std::string> out;
  for (const auto& s : schemes) out.push_back(s.name);
  return out;
}

// "8 (iqn-ils), 0 (iqn-imvj)": each quasi-Newton scheme's own default.
std::string reuse_default_text() {
  std::string out;
  for (const auto& s : accelerator_schemes())
    if (s.quasi_newton) out += (out.empty() ? "" : ", ") + std::to_string(s.default_reuse_steps) + " (" + s.name + ")";
  return out;
}

schema::Key declare_coupling() {
  using namespace schema;
  Key coupling = section(
      "coupling", "the coupling scheme (the coupler); present = a coupled run of solid and fluid",
      {
          integer("algorithm",
                  "1 = explicit solid velocity in the Robin term (Algorithm 1), 2 = implicit, adds the "
                  "damping M_fs = gamma_N1 int N^T N (Algorithm 2)")
              .req()
              .values({"1", "2"}),
          choice("scheme", {"serial", "parallel", "robin-neumann"},
                 "serial: the solid, then the fluid with its new interface state (the paper); parallel: both at "
                 "once (Jacobi), accelerated on the stacked interface state and force; robin-neumann: explicit, one "
                 "pass per step: the fluid with a Robin condition of the solid's interface inertia, then the solid "
                 "with the fluid's traction (Fernandez, Mullaert & Vidrascu 2013, 2015)")
              .def("serial"),
          integer("robin_neumann_order",
                  "scheme robin-neumann: the extrapolation of the Robin data, 1 (f* = f_n, v* = 2 v_n - v_(n-1)) or "
                  "2 (f* = 2 f_n - f_(n-1), v* = 3 v_n - 3 v_(n-1) + v_(n-2))")
              .def("1")
              .values({"1", "2"}),
          number("gamma_n1", "Nitsche penalty gamma_N1 (the Robin parameter)").req().ge(0),
          choice("robin_auto", {"none", "solid", "fluid", "both"},
                 "the Robin parameter from the solid's mass per interface measure over dt, (m_s / |Gamma|) / dt, "
                 "instead of gamma_n1 (solid: Algorithm 2's damping), of fluid_penalty (fluid), or of both")
              .def("none"),
          number(
              "fluid_penalty",
              "the fluid's Nitsche penalty gamma_f (weak v_f = v_s); default gamma_n1 (the paper: one parameter). "
              "Set apart, Algorithm 2's converged solution does not depend on gamma_n1; Algorithm 1 uses gamma_f only")
              .def_computed("gamma_n1")
              .ge(0),
          number("gamma_n2", "Nitsche symmetry switch: +1 symmetric, -1 unsymmetric (the paper)")
              .def("-1")
              .values({"1", "-1"}),
          number("relaxation", "beta: F^(k+1) = -beta F* + (1 - beta) F^(k); below 2 with Algorithm 1")
              .req()
              .gt(0)
              .says("(beta) must be > 0"),
          choice("predictor", names_of(predictor_schemes()),
                 "force predictor, extrapolating the last 1-4 accepted forces: F_n (the paper), 2 F_n - F_(n-1), "
                 "3 F_n - 3 F_(n-1) + F_(n-2), or 4 F_n - 6 F_(n-1) + 4 F_(n-2) - F_(n-3)")
              .def("previous"),
          choice("acceleration", names_of(accelerator_schemes()),
                 "constant beta (the paper), Aitken dynamic relaxation, or interface quasi-Newton: IQN-ILS (least "
                 "squares) or IQN-IMVJ (multi-vector Jacobian carried over the steps)")
              .def("constant"),
          section(
              "iqn", "interface quasi-Newton options (IQN-ILS, IQN-IMVJ; preCICE's semantics)",
              {
                  integer("reuse_steps",
                          "secant pairs are kept from the last N steps (IQN-IMVJ carries them in "
                          "its Jacobian instead)")
                      .def_computed(reuse_default_text())
                      .ge(0),
                  number("filter", "the filter's limit eps").def("0.001").gt(0).lt(1),
                  choice("filter_type", {"qr1", "qr2", "qr3"},
                         "qr1: drop columns with |R_ii| < eps ||R||_F (a limit orders below qr2's, e.g. 1e-8, as the "
                         "largest columns dominate ||R||_F); qr2: newest first, drop a column whose "
                         "orthogonal remainder is below eps x its norm; qr3: qr2's result, updating the last "
                         "iteration's QR and running qr2 only when a column fails")
                      .def("qr2"),
                  choice("preconditioner", {"none", "residual-sum"},
                         "residual-sum: each force component (x, y) weighted by the inverse of the sum of its "
                         "shares of the residual norm over the step's iterations (updated on a factor 10)")
                      .def("none"),
                  section("imvj", "IQN-IMVJ's restart",
                          {
                              choice("restart", {"none", "rs-0", "rs-ls", "rs-svd"},
                                     "none: the dense Jacobian carried over; after chunk_size steps restart "
                                     "from zero, from the least-squares Jacobian of the last steps, or from a "
                                     "truncated SVD of the accumulated Jacobian")
                                  .def("none"),
                              integer("chunk_size", "steps between restarts").def("8").ge(1).in_unit("steps"),
                              integer("restart_reuse_steps",
                                      "rs-ls: the steps whose secant pairs define the "
                                      "restart Jacobian")
                                  .def("8")
                                  .ge(1)
                                  .in_unit("steps"),
                              number("truncation",
                                     "rs-svd: singular values below this share of the largest "
                                     "are dropped")
                                  .def("0.0001")
                                  .ge(0)
                                  .lt(1),
                          })
                      .only_when("coupling.acceleration", {"iqn-imvj"}, "constant"),
              })
              .only_when("acceleration", {"iqn-ils", "iqn-imvj"}, "constant"),
          section(
              "iterations", "coupling iterations per time step",
              {
                  integer("max", "k_max, coupling iterations per step").req().ge(1),
                  number("tolerance", "relative interface residual target; 0 = always k_max iterations").def("0").ge(0),
                  boolean("stop_if_not_converged", "a step that misses the tolerance ends the run").def("true"),
                  number("divergence_factor", "a residual this many times the step's first one = diverged")
                      .def("10000")
                      .gt(1),
                  section_list("measures", "convergence measures per interface quantity (instead of tolerance)",
                               {
                                   choice("quantity", {"force", "traction", "displacement", "velocity"},
                                          "force: the relaxed force update; traction: the physical traction "
                                          "mismatch; displacement, velocity: change between iterations")
                                       .req(),
                                   choice("type", {"absolute", "relative", "residual-relative"},
                                          "|r| < limit, |r| / |q| < limit, or |r_k| / |r_1| < limit")
                                       .def("relative"),
                                   number("limit", "the bound").req().gt(0),
                                   boolean("strict", "not met in k_max iterations = the run diverged").def("false"),
                               }),
                  choice("combine", {"all", "any"}, "converged when all measures hold, or any").def("all"),
              })
              .req(),
          choice("robin_mass", {"consistent", "solid"},
                 "interface mass of the gamma_N1 terms on the solid side: the fluid's H^T M_f H in its current "
                 "configuration (cancels exactly at convergence), or the solid's own int N^T N (earlier behaviour)")
              .def("consistent"),
          choice("mapping", {"nearest-segment", "rbf-tps", "rbf-wendland-c2"},
                 "interface mapping, displacement and velocity consistent (H), forces by H^T: projection on the "
                 "solid's interface segments, or radial basis functions on the solid's nodes with a linear term "
                 "(exact for affine fields): thin-plate splines, or Wendland C2 of radius support_radius")
              .def("nearest-segment"),
          number("support_radius",
                 "rbf-wendland-c2: the support radius; default 50 x the largest distance from a "
                 "solid interface node to its nearest neighbour")
              .def_computed("50 x node spacing")
              .gt(0)
              .in_unit("m")
              .only_when("mapping", {"rbf-wendland-c2"}, "nearest-segment"),
          number("force_limit", "an interface force above this = diverged").def("1e12").gt(0).in_unit("N"),
          section("growth",
                  "unbounded growth = diverged: the largest interface displacement |d| of the last `window` "
                  "steps more than `factor` times that of the `window` steps before (a loosely coupled scheme "
                  "above its stability limit); watched from step 2 x window on",
                  {
                      number("factor", "growth over one window that ends the run as diverged").def("1000").gt(1),
                      integer("window", "steps per window").def("200").ge(1).in_unit("steps"),
                  }),
          section("interface_gap",
                  "the largest distance from a fluid interface node to the solid's interface, as a fraction "
                  "of the solid interface's median element size (segment length; in 3D the square root of "
                  "the face area): a gap this large means the two meshes are not in the same frame, units or "
                  "place",
                  {
                      number("warn", "warn above this fraction").def("0.05").ge(0),
                      number("refuse", "refuse to run above this fraction (0 = never refuse)").def("0.5").ge(0),
                  }),

      });
  coupling.check = [](const Scene& scene) { (void)read_coupling(scene.section("coupling")); };
  return coupling;
}

}  // namespace

const schema::Key& coupling_section() {
  static const schema::Key coupling = [] {
    schema::Key k = declare_coupling();
    schema::declare(k);
    return k;
  }();
  return coupling;
}

}  // namespace fsi::coupling
