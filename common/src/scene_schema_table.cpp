// The scene schema's table: every key of every section and solver model (scene_schema.hpp).
// A reader that accepts a new key gets its line here; docs/scene-reference.md is generated
// from this table (`fsi check --reference > docs/scene-reference.md`).
#include "fsi/common/scene_schema.hpp"

namespace fsi::schema {
namespace {

Key make(std::string name, Type type, std::string meaning) {
  Key k;
  k.name = std::move(name);
  k.type = type;
  k.meaning = std::move(meaning);
  return k;
}
Key number(std::string n, std::string m) { return make(std::move(n), Type::Number, std::move(m)); }
Key integer(std::string n, std::string m) { return make(std::move(n), Type::Integer, std::move(m)); }
Key boolean(std::string n, std::string m) { return make(std::move(n), Type::Bool, std::move(m)); }
Key text(std::string n, std::string m) { return make(std::move(n), Type::String, std::move(m)); }
Key choice(std::string n, std::vector<std::string> values, std::string m) {
  Key k = make(std::move(n), Type::Enum, std::move(m));
  k.allowed = std::move(values);
  return k;
}
Key vector2(std::string n, std::string m) { return make(std::move(n), Type::Vector2, std::move(m)); }
Key number_or_vector2(std::string n, std::string m) {
  return make(std::move(n), Type::NumberOrVector2, std::move(m));
}
Key names(std::string n, std::string m) { return make(std::move(n), Type::Names, std::move(m)); }
Key string_list(std::string n, std::string m) { return make(std::move(n), Type::StringList, std::move(m)); }
Key section(std::string n, std::string m, std::vector<Key> children) {
  return make(std::move(n), Type::Section, std::move(m)).with(std::move(children));
}
Key section_list(std::string n, std::string m, std::vector<Key> children) {
  return make(std::move(n), Type::SectionList, std::move(m)).with(std::move(children));
}
Key named_map(std::string n, std::string m, Key value) {
  return make(std::move(n), Type::NamedMap, std::move(m)).with({std::move(value)});
}

std::vector<Key> time_keys() {
  return {
      number("dt", "time step").req().gt(0).in_unit("s"),
      number("end", "final time; a whole number of time steps").req().gt(0).in_unit("s"),
      integer("output_every", "VTK of both solvers (and the coupling interfaces) every N steps and at t = 0; "
                              "0 = none")
          .def("0").ge(0).in_unit("steps"),
      integer("checkpoint_every", "coupled runs: a checkpoint of both solvers and the coupler every N accepted "
                                  "steps; 0 = none")
          .def("0").ge(0).in_unit("steps"),
      integer("checkpoint_keep", "the newest K complete checkpoints are kept").def("2").ge(1),
  };
}

std::vector<Key> coupling_keys() {
  return {
      integer("algorithm", "1 = explicit solid velocity in the Robin term (Algorithm 1), 2 = implicit, adds the "
                           "damping M_fs = gamma_N1 int N^T N (Algorithm 2)")
          .req()
          .values({"1", "2"}),
      number("gamma_n1", "Nitsche penalty gamma_N1 (the Robin parameter)").req().ge(0),
      number("fluid_penalty",
             "the fluid's Nitsche penalty gamma_f (weak v_f = v_s); default gamma_n1 (the paper: one parameter). "
             "Set apart, Algorithm 2's converged solution does not depend on gamma_n1; Algorithm 1 uses gamma_f only")
          .def("gamma_n1")
          .ge(0),
      number("gamma_n2", "Nitsche symmetry switch: +1 symmetric, -1 unsymmetric (the paper)")
          .def("-1")
          .values({"1", "-1"}),
      number("relaxation", "beta: F^(k+1) = -beta F* + (1 - beta) F^(k); below 2 with Algorithm 1").req().gt(0).says("(beta) must be > 0"),
      choice("predictor", {"previous", "linear", "quadratic", "cubic"},
             "force predictor, extrapolating the last 1-4 accepted forces: F_n (the paper), 2 F_n - F_(n-1), "
             "3 F_n - 3 F_(n-1) + F_(n-2), or 4 F_n - 6 F_(n-1) + 4 F_(n-2) - F_(n-3)")
          .def("previous"),
      choice("acceleration", {"constant", "aitken", "iqn-ils", "iqn-imvj"},
             "constant beta (the paper), Aitken dynamic relaxation, or interface quasi-Newton: IQN-ILS (least "
             "squares) or IQN-IMVJ (multi-vector Jacobian carried over the steps)")
          .def("constant"),
      section("iqn", "interface quasi-Newton options (IQN-ILS, IQN-IMVJ; preCICE's semantics)",
              {
                  integer("reuse_steps", "secant pairs are kept from the last N steps (IQN-IMVJ carries them in "
                                         "its Jacobian instead)")
                      .def("8 (iqn-ils), 0 (iqn-imvj)")
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
                              integer("restart_reuse_steps", "rs-ls: the steps whose secant pairs define the "
                                                             "restart Jacobian")
                                  .def("8")
                                  .ge(1)
                                  .in_unit("steps"),
                              number("truncation", "rs-svd: singular values below this share of the largest "
                                                   "are dropped")
                                  .def("0.0001")
                                  .ge(0)
                                  .lt(1),
                          })
                      .only_when("coupling.acceleration", {"iqn-imvj"}, "constant"),
              })
          .only_when("acceleration", {"iqn-ils", "iqn-imvj"}, "constant"),
      section("iterations", "coupling iterations per time step",
              {
                  integer("max", "k_max, coupling iterations per step").req().ge(1),
                  number("tolerance", "relative interface residual target; 0 = always k_max iterations")
                      .def("0")
                      .ge(0),
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
      number("force_limit", "an interface force above this = diverged").def("1e12").gt(0).in_unit("N"),
  };
}

std::vector<Key> sdof_keys() {
  return {
      number("mass", "m").req().gt(0).in_unit("kg"),
      number("damping", "c").def("0").ge(0).in_unit("N s/m"),
      number("stiffness", "k").def("0").ge(0).in_unit("N/m"),
      number("interface_measure", "M_G: Algorithm 2 adds m_fs = gamma_N1 * measure").def("1").gt(0),
      number_or_vector2("force", "external force on the solid itself").def("0").in_unit("N"),
      number_or_vector2("initial_displacement", "d_0").def("0").in_unit("m"),
      number_or_vector2("initial_velocity", "v_0").def("0").in_unit("m/s"),
  };
}

std::vector<Key> fem_solid_keys() {
  return {
      section("mesh", "the solid mesh",
              {
                  choice("type", {"rectangle", "gmsh"}, "built-in structured Q4 rectangle, or a gmsh .msh file")
                      .req(),
                  vector2("origin", "lower-left corner").req().only_when("type", {"rectangle"}).in_unit("m"),
                  vector2("size", "lx, ly (positive)").req().only_when("type", {"rectangle"}).in_unit("m"),
                  make("elements", Type::IntList, "nx, ny Q4 cells (>= 1); edge sets left, right, bottom, top")
                      .req()
                      .count(2)
                      .only_when("type", {"rectangle"}),
                  text("file", "gmsh mesh, relative to the scene file").req().only_when("type", {"gmsh"}),
                  text("domain", "2D physical group of the solid; default: every quad group")
                      .only_when("type", {"gmsh"}),
              })
          .req(),
      section("material", "hyperelastic material (plane strain); exactly one of youngs_modulus, shear_modulus",
              {
                  choice("law", {"saint_venant_kirchhoff", "svk", "neo_hookean"}, "material law").req(),
                  number("poisson_ratio", "nu").req().gt(-1).lt(0.5),
                  number("youngs_modulus", "E").gt(0).group("modulus").in_unit("Pa"),
                  number("shear_modulus", "mu").gt(0).group("modulus").in_unit("Pa"),
              })
          .req(),
      choice("element", {"q4", "q4_eas"},
             "bilinear Q4, or Q4 with enhanced assumed strains (no shear locking in bending; same nodes)")
          .def("q4"),
      number("density", "rho_s, reference configuration").req().gt(0).in_unit("kg/m^3"),
      vector2("gravity", "body force per unit mass").def("[0, 0]").in_unit("m/s^2"),
      choice("analysis", {"static", "dynamic"}, "equilibrium every step, or dynamics").def("dynamic"),
      choice("time_scheme", {"bdf1", "bdf2", "newmark"}, "dynamic analysis: BDF1 (the paper), BDF2 or Newmark "
                                                         "(trapezoidal)")
          .def("newmark"),
      integer("load_steps", "load increments per step").def("1").ge(1),
      section("newton", "Newton iterations",
              {
                  integer("max_iterations", "per load step / time step").def("25").ge(1),
                  number("residual_tolerance", "|R| <= tol * max(|R_0|, |F_ext|)").def("1e-08").gt(0),
                  number("increment_tolerance", "or |du| <= tol * |u|").def("1e-10").ge(0),
              }),
      choice("linear_solver", {"cholmod", "umfpack"}, "sparse solver of the tangent").def("cholmod"),
      names("clamp", "edge set(s) with u = 0").def("none"),
      names("interface", "edge set(s) on the fluid side (coupling, Algorithm 2 damping)").def("none"),
      section_list("tractions", "dead edge loads",
                   {
                       names("boundary", "edge set(s)").req(),
                       vector2("traction", "force per reference length").req().in_unit("N/m"),
                   })
          .def("[]"),
      section_list("point_loads", "dead loads at the node nearest to a point",
                   {
                       vector2("point", "where").req().in_unit("m"),
                       vector2("force", "the load").req().in_unit("N"),
                   })
          .def("[]"),
      section_list("probes", "displacement of points (probes NAME_x, NAME_y)",
                   {
                       text("name", "probe name").req(),
                       vector2("point", "a point inside the mesh").req().in_unit("m"),
                   })
          .def("[]"),
      integer("output_every", "VTK when the run writes output (time.output_every) and step % N == 0; 0 = never")
          .def("1")
          .ge(0)
          .in_unit("steps"),
  };
}

std::vector<Key> surrogate_keys() {
  return {
      number_or_vector2("force", "F, the constant fluid force on the solid").def("0").in_unit("N"),
      number("added_mass", "m_a: the force is F - m_a a").def("0").ge(0).in_unit("kg"),
      number("interface_measure", "M_G of the point interface").def("1").gt(0),
  };
}

std::vector<Key> fem_fluid_keys() {
  const std::string element = "fluid.element";
  return {
      choice("element", {"p1p1", "p2p1"}, "P1/P1 with SUPG/PSPG, or isoparametric Taylor-Hood P2/P1").def("p1p1"),
      section("mesh", "the fluid mesh: a gmsh .msh file, or a .geo meshed by gmsh (cached)",
              {
                  text("file", "gmsh .msh, relative to the scene file (or the working folder, or configs/)")
                      .group("source"),
                  text("geo", "gmsh .geo, meshed once per parameter set into the mesh cache").group("source"),
                  number("size", "element size h far from the body").req().gt(0).only_when("geo").in_unit("m"),
                  named_map("parameters",
                            "further gmsh -setnumber values, name: number (meshes/th_cylinder_flag.geo: hc, hw, "
                            "algorithm, nflag and nflagt for a conforming flag; see its header)",
                            number("<name>", "value"))
                      .only_when("geo"),
                  text("cache_dir", "mesh cache; default $FSI_MESH_CACHE, else ~/.cache/fsi/meshes")
                      .only_when("geo"),
                  string_list("domain", "2D physical group(s) of the fluid; default: every triangle group"),
              })
          .req(),
      number("density", "rho_f").req().gt(0).in_unit("kg/m^3"),
      number("viscosity", "dynamic viscosity mu_f").req().gt(0).in_unit("Pa s"),
      choice("scheme", {"bdf1", "bdf2", "steady"}, "time scheme").def("bdf2"),
      section("nonlinear", "nonlinear iterations per step",
              {
                  integer("max_iterations", "nonlinear solves per step; 1 = semi-implicit").def("1").ge(1),
                  number("tolerance", "relative velocity change").def("1e-10"),
                  boolean("relinearise", "a coupling iteration linearises about the last solve").def("false"),
                  choice("method", {"picard", "newton"}, "Oseen iterations or Newton")
                      .def("newton for steady P2/P1, else picard"),
              }),
      section("stabilisation", "SUPG/PSPG/LSIC (P1/P1) or SUPG/grad-div (P2/P1)",
              {
                  boolean("supg", "streamline upwind Petrov-Galerkin").def("true (P1/P1), false (P2/P1)"),
                  number("viscous_constant", "c in tau_M^-2 = (2/dt)^2 + (2|a|/h)^2 + (c 4 nu/h^2)^2").def("3"),
                  boolean("transient_tau", "include the (2/dt)^2 term in tau_M").def("true"),
                  boolean("pspg", "pressure-stabilising Petrov-Galerkin").def("true").only_when(element, {"p1p1"},
                                                                                               "p1p1"),
                  number("lsic_scale", "multiplies tau_C = h^2 / (8 tau_M); 0 = no LSIC")
                      .def("1")
                      .only_when(element, {"p1p1"}, "p1p1"),
                  boolean("viscous_residual", "include the reconstructed div(mu grad u) in the residual")
                      .def("false")
                      .only_when(element, {"p1p1"}, "p1p1"),
                  number("grad_div", "gamma in gamma (div w, div u)")
                      .def("0")
                      .ge(0)
                      .in_unit("Pa s")
                      .only_when(element, {"p2p1"}, "p1p1"),
              }),
      integer("threads", "assembly threads (OpenMP)").def("1"),
      integer("umfpack_irstep", "UMFPACK iterative refinement steps").def("0").ge(0).le(2),
      section("linear_solver", "sparse LU (UMFPACK) and its reuse as a BiCGSTAB preconditioner",
              {
                  choice("ordering", {"auto", "metis", "amd"}, "fill-reducing ordering").def("auto"),
                  choice("strategy", {"auto", "symmetric", "unsymmetric"}, "UMFPACK strategy")
                      .def("symmetric (P2/P1), auto (P1/P1)"),
                  boolean("reuse_factorisation", "precondition BiCGSTAB with the last LU factors").def("true"),
                  number("krylov_tolerance", "relative residual of BiCGSTAB").def("1e-10"),
                  integer("krylov_max_iterations", "more = refactorise").def("25"),
                  integer("krylov_refactor_iterations", "a solve needing more marks the factors stale").def("8"),
                  boolean("adaptive_refactorisation", "refactorise when that is cheaper per solve").def("true"),
              }),
      section("interface", "the fluid-structure interface",
              {
                  string_list("groups", "boundary group(s) of the interface").def("[]"),
                  number("penalty", "gamma_N1 of standalone runs (coupled: coupling.gamma_n1)").def("0").ge(0),
                  choice("penalty_geometry", {"current", "step_start"},
                         "the Nitsche penalty term (and f_v, M_f) on the interface of this solve, or of the last "
                         "accepted step (M_G constant within a step: robust converged Algorithm 2 at large gamma_N1)")
                      .def("current"),
                  number("symmetry", "gamma_N2 of standalone runs (coupled: coupling.gamma_n2)")
                      .def("-1")
                      .values({"1", "-1"}),
                  number("mesh_stiffening", "mesh motion: stiffening of small elements").def("1").only_when("groups"),
                  choice("mesh_motion", {"harmonic", "elastic"}, "mesh motion: the extension of the interface "
                                                                 "displacement")
                      .def("harmonic")
                      .only_when("groups"),
                  boolean("mesh_incremental", "mesh motion from the last configuration").def("false").only_when(
                      "groups"),
                  choice("mesh_motion_nodes", {"vertices", "all"}, "P2 meshes: extend on the vertices or on every "
                                                                   "node")
                      .def("vertices")
                      .only_when("groups")
                      .only_when(element, {"p2p1"}, "p1p1"),
              }),
      text("initial_state", "fluid.state of another run's checkpoint (fsi run --initial-state RUN_DIR): start from "
                            "its velocity and pressure, interpolated onto this mesh"),
      section("remesh", "remeshing when the moving mesh's quality drops (boundary nodes kept, interior by gmsh)",
              {
                  boolean("enabled", "remesh when the quality falls below min_quality").def(
                      "true with fluid.interface.groups"),
                  number("min_quality", "minimum scaled Jacobian that triggers a remesh").def("0.1").lt(1),
                  number("min_curved_jacobian", "P2: minimum relative curved Jacobian that triggers a remesh")
                      .def("0.3")
                      .only_when(element, {"p2p1"}, "p1p1"),
                  make("at_steps", Type::IntList, "remesh after these steps in any case (tests)"),
              }),
      section_list("inflow", "velocity inlets",
                   {
                       text("group", "boundary group").req(),
                       choice("profile", {"parabolic", "uniform"}, "velocity profile").def("parabolic"),
                       number("max_velocity", "peak velocity").group("velocity").in_unit("m/s"),
                       number("mean_velocity", "mean velocity (parabolic: peak = 1.5 mean)")
                           .group("velocity")
                           .in_unit("m/s"),
                       vector2("direction", "flow direction").def("[1, 0]"),
                       number("ramp_time", "(1 - cos) ramp from 0").def("0").in_unit("s"),
                       make("profile_extent", Type::PointPair, "[[x0, y0], [x1, y1]]: ends of the full profile")
                           .in_unit("m"),
                       section("pulsation", "factor mean + amplitude sin(2 pi frequency t)",
                               {
                                   number("mean", "mean factor").def("1"),
                                   number("amplitude", "amplitude").req(),
                                   number("frequency", "frequency").req().in_unit("Hz"),
                               }),
                   })
          .def("[]"),
      string_list("walls", "no-slip boundary groups").def("[]"),
      section_list("moving_walls", "boundary groups with a given velocity",
                   {
                       text("group", "boundary group").req(),
                       vector2("velocity", "wall velocity").req().in_unit("m/s"),
                   })
          .def("[]"),
      string_list("symmetry", "symmetry (slip) boundary groups").def("[]"),
      string_list("outlet", "do-nothing outlets").def("[]"),
      section("pressure_reference", "pins the pressure at a point",
              {
                  vector2("point", "where").req().in_unit("m"),
                  number("value", "pressure there").def("0").in_unit("Pa"),
              }),
      section_list("forces", "force probes (NAMEdrag, NAMElift)",
                   {
                       text("name", "probe prefix").def("\"\""),
                       string_list("groups", "boundary group(s)").req(),
                       number("reference_velocity", "with reference_length: coefficients C_D, C_L").in_unit("m/s"),
                       number("reference_length", "reference length").req().only_when("reference_velocity").in_unit(
                           "m"),
                   })
          .def("[]"),
      named_map("pressure_probes", "pressure at points, name: [x, y]", vector2("<name>", "point").in_unit("m")),
      named_map("pressure_differences", "name: [high, low] (two pressure probes)",
                make("<name>", Type::StringList, "two pressure probe names").count(2)),
      section("output", "fluid output",
              {
                  integer("vtk_every", "VTK only at steps that are multiples of N; 0 = never; default: every "
                                       "output step")
                      .ge(0)
                      .in_unit("steps"),
              }),
  };
}

std::vector<Key> build() {
  Key solid = section("solid", "the solid solver (solid_server)", {});
  solid.selector = "model";
  solid.variants = {
      {"sdof", "single-degree-of-freedom point solid m a + c v + k d = F", sdof_keys()},
      {"fem", "finite-strain Q4 solid (Saint Venant-Kirchhoff or neo-Hookean)", fem_solid_keys()},
  };
  Key fluid = section("fluid", "the fluid solver (fluid_server)", {});
  fluid.selector = "model";
  fluid.variants = {
      {"surrogate", "constant force with an added mass at one point", surrogate_keys()},
      {"fem", "incompressible Navier-Stokes on a moving (ALE) mesh, P1/P1 or P2/P1", fem_fluid_keys()},
  };
  return {
      text("scene", "the scene's name"),
      text("description", "one line about the scene"),
      section("time", "time stepping (every runner)", time_keys()).req(),
      section("coupling", "the coupling scheme (the coupler); present = a coupled run of solid and fluid",
              coupling_keys()),
      solid,
      fluid,
  };
}

}  // namespace

const std::vector<Key>& scene_keys() {
  static const std::vector<Key> keys = build();
  return keys;
}

}  // namespace fsi::schema
