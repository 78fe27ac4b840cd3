// The keys of `fluid.model: fem`, declared once beside their reader (navier_stokes_fluid.cpp).
#include "fsi/common/scene_schema.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"

namespace fsi::fluid {

const std::vector<schema::Key>& navier_stokes_keys() {
  using namespace schema;
  const std::string element = "fluid.element";
  static const std::vector<Key> keys = {
      choice("element", {"p1p1", "p2p1"}, "P1/P1 with SUPG/PSPG, or isoparametric Taylor-Hood P2/P1").def("p1p1"),
      choice("dimension", {"2", "3"},
             "2: triangles; 3: tetrahedra (p2p1, steady or BDF; points and directions [x, y, z]; interface "
             "faces of 6-node triangles)")
          .def("2"),
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
                  text("cache_dir", "mesh cache; default $FSI_MESH_CACHE, else ~/.cache/fsi/meshes").only_when("geo"),
                  string_list("domain", "2D physical group(s) of the fluid; default: every triangle group"),
              })
          .req(),
      number("density", "rho_f").req().gt(0).in_unit("kg/m^3"),
      number("viscosity", "dynamic viscosity mu_f").req().gt(0).in_unit("Pa s"),
      number("backflow_stabilisation",
             "3D: beta of the backflow stabilisation of the traction-free boundaries (outlet; pressures while their "
             "pressure is 0): where fluid enters through them their traction gains beta rho min((u - w).n, 0) u "
             "(Bazilevs et al. 2009); 0 = off")
          .def("0")
          .ge(0),
      choice("scheme", {"bdf1", "bdf2", "steady"}, "time scheme").def("bdf2"),
      section("nonlinear", "nonlinear iterations per step",
              {
                  integer("max_iterations", "nonlinear solves per step; 1 = semi-implicit").def("1").ge(1),
                  number("tolerance", "relative velocity change").def("1e-10"),
                  boolean("relinearise", "a coupling iteration linearises about the last solve").def("false"),
                  choice("method", {"picard", "newton"}, "Oseen iterations or Newton")
                      .def_computed("newton for steady P2/P1, else picard"),
              }),
      section(
          "stabilisation", "SUPG/PSPG/LSIC (P1/P1) or SUPG/grad-div (P2/P1)",
          {
              boolean("supg", "streamline upwind Petrov-Galerkin").def_computed("true (P1/P1), false (P2/P1)"),
              number("viscous_constant", "c in tau_M^-2 = (2/dt)^2 + (2|a|/h)^2 + (c 4 nu/h^2)^2").def("3"),
              boolean("transient_tau", "include the (2/dt)^2 term in tau_M").def("true"),
              boolean("pspg", "pressure-stabilising Petrov-Galerkin").def("true").only_when(element, {"p1p1"}, "p1p1"),
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
      integer("ranks",
              "MPI ranks of the fluid (fsi run starts fluid_server under mpirun -n N; engine petsc or mumps): "
              "all ranks solve; in 3D all ranks assemble (fluid.mpi.assembly)")
          .def("1")
          .ge(1),
      section(
          "mpi", "how fsi run starts a fluid with ranks > 1",
          {
              text("command", "the MPI launcher (PATH is searched)").def("mpirun"),
              text("hostfile", "mpirun --hostfile: the hosts of the ranks (relative to the scene file)"),
              string_list("args", "further launcher arguments, e.g. [--oversubscribe] or [--host, a:2,b:2]").def("[]"),
              choice("assembly", {"partitioned", "distributed", "rank0"},
                     "3D: partitioned = each rank keeps only its block of cells and adds their element matrices to "
                     "its rows of the distributed matrix; distributed = every rank computes the element matrices "
                     "of its block and rank 0 sums them into the whole matrix; rank0 = rank 0 assembles alone (2D "
                     "always does)")
                  .def("partitioned"),
          }),
      integer("umfpack_irstep", "UMFPACK iterative refinement steps").def("0").ge(0).le(2),
      section("linear_solver",
              "the linear-algebra engine: sparse LU (UMFPACK) and its reuse as a BiCGSTAB preconditioner, or PETSc "
              "(docs/fluid.md, Linear-algebra engines)",
              {
                  choice("engine", {"umfpack", "petsc", "mumps"},
                         "umfpack: UMFPACK LU (the settings below); petsc: PETSc GMRES with a field-split Schur "
                         "preconditioner (ILU(0) velocity, BoomerAMG on the selfp Schur complement); mumps: the "
                         "MUMPS direct solver through PETSc")
                      .def_computed("umfpack in 2D; petsc in 3D (umfpack in a build without PETSc)"),
                  text("petsc_options",
                       "petsc / mumps: further PETSc options after the engine's defaults, e.g. \"-ksp_rtol 1e-12\" "
                       "(the KSP's and its PC's options, sub-solvers as -fieldsplit_u_* / -fieldsplit_p_*); an "
                       "option the solver does not use is refused")
                      .def("\"\""),
                  boolean("petsc_reuse_preconditioner",
                          "petsc: keep the preconditioner of an earlier matrix while it works (a kept one that "
                          "needs more iterations than petsc_rebuild_factor allows is replaced within the solve)")
                      .def_computed("false when steady (Newton iterations), true with BDF time steps"),
                  number("petsc_rebuild_factor",
                         "petsc: rebuild once a solve needs more than this times the iterations of the "
                         "preconditioner's first solve (+ 5)")
                      .def("1.5")
                      .ge(1),
                  choice("ordering", {"auto", "metis", "amd"}, "fill-reducing ordering").def("auto"),
                  choice("strategy", {"auto", "symmetric", "unsymmetric"}, "UMFPACK strategy")
                      .def_computed("symmetric (P2/P1), auto (P1/P1)"),
                  boolean("reuse_factorisation", "precondition BiCGSTAB with the last LU factors").def("true"),
                  number("krylov_tolerance", "relative residual of BiCGSTAB").def("1e-10"),
                  integer("krylov_max_iterations", "more = refactorise").def("25"),
                  integer("krylov_refactor_iterations", "a solve needing more marks the factors stale").def("8"),
                  boolean("adaptive_refactorisation", "refactorise when that is cheaper per solve").def("true"),
              }),
      section(
          "interface", "the fluid-structure interface",
          {
              string_list("groups", "boundary group(s) of the interface").def("[]"),
              number("penalty", "gamma_N1 of standalone runs (coupled: coupling.gamma_n1)").def_computed("0").ge(0),
              choice("penalty_geometry", {"current", "step_start"},
                     "the Nitsche penalty term (and f_v, M_f) on the interface of this solve, or of the last "
                     "accepted step (M_G constant within a step: robust converged Algorithm 2 at large gamma_N1)")
                  .def("current"),
              number("symmetry", "gamma_N2 of standalone runs (coupled: coupling.gamma_n2)")
                  .def_computed("-1")
                  .values({"1", "-1"}),
              number("mesh_stiffening", "mesh motion: stiffening of small elements").def("1").only_when("groups"),
              choice("mesh_motion", {"harmonic", "elastic"},
                     "mesh motion: the extension of the interface "
                     "displacement")
                  .def("harmonic")
                  .only_when("groups"),
              boolean("mesh_incremental", "mesh motion from the last configuration").def("false").only_when("groups"),
              choice("mesh_motion_nodes", {"vertices", "all"},
                     "P2 meshes: extend on the vertices or on every "
                     "node")
                  .def("vertices")
                  .only_when("groups")
                  .only_when(element, {"p2p1"}, "p1p1"),
          }),
      text("initial_state",
           "fluid.state of another run's checkpoint (fsi run --initial-state RUN_DIR): start from "
           "its velocity and pressure, interpolated onto this mesh"),
      section("remesh", "remeshing when the moving mesh's quality drops (boundary nodes kept, interior by gmsh)",
              {
                  boolean("enabled", "remesh when the quality falls below min_quality")
                      .def_computed("true with fluid.interface.groups"),
                  number("min_quality", "minimum scaled Jacobian that triggers a remesh").def("0.1").lt(1),
                  number("min_curved_jacobian", "P2: minimum relative curved Jacobian that triggers a remesh")
                      .def("0.3")
                      .only_when(element, {"p2p1"}, "p1p1"),
                  int_list("at_steps", 0, "remesh after these steps in any case (tests)").ge(1),
              }),
      section_list(
          "inflow", "velocity inlets",
          {
              text("group", "boundary group").req(),
              choice("profile", {"parabolic", "uniform"}, "velocity profile").def("parabolic"),
              number("max_velocity", "peak velocity").group("velocity").in_unit("m/s"),
              number("mean_velocity", "mean velocity (parabolic: peak = 1.5 mean)").group("velocity").in_unit("m/s"),
              vector2("direction", "flow direction ([x, y, z] in 3D)").def("[1, 0]").count(3),
              number("ramp_time", "(1 - cos) ramp from 0").def("0").in_unit("s"),
              point_pair("profile_extent", "[[x0, y0], [x1, y1]]: ends of the full profile").in_unit("m"),
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
      section_list("pressures",
                   "pressure inlets/outlets: the normal traction (mu grad u - p I) n = -p n (p2p1), p from "
                   "start_time to end_time, 0 outside",
                   {
                       text("group", "boundary group").req(),
                       number("pressure", "p").req().in_unit("Pa"),
                       number("start_time", "applied from").def("0").in_unit("s"),
                       number("end_time", "applied until (default: always)").in_unit("s"),
                   })
          .def("[]"),
      section("pressure_reference", "pins the pressure at a point",
              {
                  vector2("point", "where").req().in_unit("m"),
                  number("value", "pressure there").def("0").in_unit("Pa"),
              }),
      section_list(
          "forces", "force probes (NAMEdrag, NAMElift)",
          {
              text("name", "probe prefix").def("\"\""),
              string_list("groups", "boundary group(s)").req(),
              number("reference_velocity", "with reference_length: coefficients C_D, C_L").in_unit("m/s"),
              number("reference_length", "reference length").req().only_when("reference_velocity").in_unit("m"),
          })
          .def("[]"),
      named_map("pressure_probes", "pressure at points, name: [x, y] ([x, y, z] in 3D)",
                vector2("<name>", "point").in_unit("m").count(3)),
      named_map("pressure_differences", "name: [high, low] (two pressure probes)",
                string_list("<name>", "two pressure probe names").count(2)),
      section("output", "fluid output",
              {
                  integer("vtk_every",
                          "VTK only at steps that are multiples of N; 0 = never; default: every "
                          "output step")
                      .ge(0)
                      .in_unit("steps"),
              }),
  };
  return keys;
}

}  // namespace fsi::fluid
