#include "fsi/fluid/navier_stokes_fluid.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "fsi/common/gmsh_reader.hpp"
#include "fsi/common/log.hpp"
#include "fsi/common/scene_reader.hpp"
#include "fsi/fluid/field_transfer.hpp"
#include "fsi/fluid/flow_vtk.hpp"
#include "fsi/fluid/linear_solver.hpp"
#include "fsi/fluid/mesh_quality.hpp"
#include "fsi/fluid/remesh.hpp"

namespace fsi::fluid {
namespace {

std::vector<std::string> string_list(const schema::Reader& section, const std::string& key) {
  return section.get<std::vector<std::string>>(key);
}

Eigen::Vector2d vector2(const schema::Reader& section, const std::string& key) {
  const auto v = section.vector2(key);
  return {v[0], v[1]};
}

// A point of a map whose names the user chooses (pressure_probes: name: [x, y]).
Eigen::Vector2d named_point(const ConfigSection& map, const std::string& name) {
  const auto v = map.get<std::vector<double>>(name);
  if (v.size() != 2) map.fail(name, fmt::format("must be a list of 2 numbers, got {}", v.size()));
  return {v[0], v[1]};
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// --- fluid.mesh ---

// The mesh cache: fluid.mesh.cache_dir, else the default (fsi/common/gmsh_mesher.hpp).
std::filesystem::path mesh_cache(const schema::Reader& mesh_section) {
  if (mesh_section.has("cache_dir")) return mesh_section.get<std::string>("cache_dir");
  return default_mesh_cache();
}

// The .msh file: fluid.mesh.file, or fluid.mesh.geo meshed by gmsh (cached) with the size h,
// the further parameters and the element order.
std::filesystem::path mesh_file(const schema::Reader& mesh_section, int order, int dimension = 2) {
  if (mesh_section.has("file")) return mesh_section.path("file");
  const auto geo = mesh_section.path("geo");
  std::map<std::string, double> parameters;
  parameters["h"] = mesh_section.get<double>("size");
  (void)mesh_section.declared("parameters");
  if (auto extra = mesh_section.section().optional_child("parameters"))
    for (const auto& k : extra->keys()) parameters[k] = extra->get<double>(k);
  return mesh_geo(geo, parameters, mesh_cache(mesh_section), order, dimension);
}

// The mesh of `msh` in the element's order (P2/P1: a linear mesh gets straight midpoints).
FluidMesh read_mesh(const schema::Reader& mesh_section, const std::filesystem::path& msh, bool taylor_hood) {
  const auto domain = mesh_section.get_or<std::vector<std::string>>("domain", {});
  FluidMesh mesh;
  try {
    mesh = FluidMesh::from_gmsh(read_gmsh(msh), domain);
  } catch (const fsi::ConfigError&) {
    throw;
  } catch (const std::exception& e) {
    if (mesh_section.has("file")) throw;
    // The user wrote the .geo: name it, not the cache file gmsh wrote from it.
    mesh_section.fail("geo", fmt::format("gmsh meshed it, but the mesh cannot be used ({}): a .geo needs a plane "
                                         "surface and the physical groups of fluid.mesh.domain and the boundaries",
                                         e.what()));
  }
  if (taylor_hood && !mesh.quadratic()) {
    fsi::logger("fluid")->info(
        "fluid: {} has 3-node triangles; the P2/P1 elements get straight edges (mesh with gmsh "
        "-order 2 for curved boundaries)",
        msh.string());
    mesh = mesh.quadratic_from_linear();
  } else if (!taylor_hood && mesh.quadratic()) {
    mesh_section.fail(mesh_section.has("file") ? "file" : "geo",
                      "the mesh has 6-node triangles, the P1/P1 fluid needs 3-node ones (or set fluid.element: p2p1)");
  }
  return mesh;
}

// --- physics and numerics ---

// density, viscosity, scheme, nonlinear.
void read_physics(const schema::Reader& section, bool taylor_hood, FlowParameters& params) {
  params.density = section.get<double>("density");
  params.viscosity = section.get<double>("viscosity");
  params.backflow_beta = section.get<double>("backflow_stabilisation");
  const auto scheme = section.get<std::string>("scheme");
  params.scheme = scheme == "bdf1" ? TimeScheme::BDF1 : scheme == "steady" ? TimeScheme::Steady : TimeScheme::BDF2;
  // Steady Taylor-Hood problems default to Newton (P1/P1: Picard, as validated; newton on request:
  // the Galerkin Jacobian with Picard stabilisation terms, so it converges fast but not quadratically).
  std::string method = taylor_hood && params.scheme == TimeScheme::Steady ? "newton" : "picard";
  {
    const auto nl = section.child_or_defaults("nonlinear");
    params.max_iterations = nl.get<int>("max_iterations");
    params.tolerance = nl.get<double>("tolerance");
    params.relinearise = nl.get<bool>("relinearise");
    method = nl.get_or<std::string>("method", method);
  }
  params.newton = method == "newton";
  if (params.scheme == TimeScheme::Steady && params.max_iterations == 1) params.max_iterations = 50;
}

// fluid.stabilisation: each element's own keys (the other element's are refused).
void read_stabilisation(const schema::Reader& section, bool taylor_hood, StabilisationParameters& s) {
  if (taylor_hood) {
    // Taylor-Hood is inf-sup stable: no PSPG; SUPG and grad-div only when asked for.
    s.supg = false;
    s.pspg = false;
    s.lsic_scale = 0;
  }
  const auto st = section.optional_child("stabilisation");
  if (!st) return;
  s.supg = st->get_or<bool>("supg", s.supg);
  s.viscous_constant = st->get<double>("viscous_constant");
  s.transient_tau = st->get<bool>("transient_tau");
  if (taylor_hood) {
    for (const char* key : {"pspg", "lsic_scale", "viscous_residual"})
      if (st->has(key))
        st->fail(key, "is a P1/P1 setting; the P2/P1 element takes supg, grad_div, viscous_constant, transient_tau");
    s.grad_div = st->get<double>("grad_div");
  } else {
    if (st->has("grad_div")) st->fail("grad_div", "is a P2/P1 setting; the P1/P1 element takes lsic_scale");
    s.pspg = st->get<bool>("pspg");
    s.lsic_scale = st->get<double>("lsic_scale");
    s.viscous_residual = st->get<bool>("viscous_residual");
  }
}

// threads, umfpack_irstep, ranks, linear_solver. The default engine: UMFPACK in 2D; PETSc in 3D
// when built with it (DFG 3D-1Z: 2.6x faster than UMFPACK at 31.6k unknowns, 4.8x at 76.8k with
// 42 % of its memory; docs/fluid.md).
void read_linear_solver(const schema::Reader& section, bool taylor_hood, int dimension, FlowParameters& params) {
  params.threads = section.get<int>("threads");
  params.umfpack_irstep = section.get<int>("umfpack_irstep");
  if (taylor_hood) params.strategy = LuStrategy::Symmetric;
  const auto ls = section.optional_child("linear_solver");
  // Measured on DFG 3D-1Z (docs/fluid.md): the matrices of successive Newton iterations differ
  // too much for a kept preconditioner (twice the iterations); time steps differ little.
  params.petsc_reuse_preconditioner = params.scheme != TimeScheme::Steady;
  params.engine = dimension == 3 && petsc_available() ? LinearEngine::Petsc : LinearEngine::Umfpack;
  const int ranks = section.get<int>("ranks");
  // fluid.mpi: the launcher's keys (fsi run), and how the ranks share the assembly.
  const auto assembly = section.child_or_defaults("mpi").get<std::string>("assembly");
  params.distributed_assembly = assembly != "rank0";
  params.partitioned_assembly = assembly == "partitioned";
  if (ranks != mpi_world_size())
    section.fail("ranks", fmt::format("is {} but this fluid_server runs on {} MPI rank(s): fsi run starts it under "
                                      "mpirun -n {} (or start it so yourself)",
                                      ranks, mpi_world_size(), ranks));
  if (!ls) {
    if (ranks > 1 && params.engine == LinearEngine::Umfpack)
      section.fail("ranks", "needs fluid.linear_solver.engine: petsc or mumps (UMFPACK runs on one rank)");
    return;
  }
  const auto engine = ls->get_or<std::string>("engine", params.engine == LinearEngine::Petsc ? "petsc" : "umfpack");
  params.engine = engine == "petsc"   ? LinearEngine::Petsc
                  : engine == "mumps" ? LinearEngine::Mumps
                                      : LinearEngine::Umfpack;
  if (ranks > 1 && params.engine == LinearEngine::Umfpack)
    section.fail("ranks", "needs fluid.linear_solver.engine: petsc or mumps (UMFPACK runs on one rank)");
  if (params.engine != LinearEngine::Umfpack && !petsc_available())
    ls->fail("engine", "this build has no PETSc (install libpetsc-real-dev, scripts/install-deps.sh, and reconfigure)");
  params.petsc_options = ls->get<std::string>("petsc_options");
  if (params.engine == LinearEngine::Umfpack && !params.petsc_options.empty())
    ls->fail("petsc_options", "is for the petsc and mumps engines (engine is umfpack)");
  params.petsc_reuse_preconditioner = ls->get_or<bool>("petsc_reuse_preconditioner", params.petsc_reuse_preconditioner);
  params.petsc_rebuild_factor = ls->get<double>("petsc_rebuild_factor");
  const auto ordering = ls->get<std::string>("ordering");
  params.ordering = ordering == "metis" ? Ordering::Metis : ordering == "amd" ? Ordering::Amd : Ordering::Auto;
  const auto strategy = ls->get_or<std::string>("strategy", taylor_hood ? "symmetric" : "auto");
  params.strategy = strategy == "symmetric"     ? LuStrategy::Symmetric
                    : strategy == "unsymmetric" ? LuStrategy::Unsymmetric
                                                : LuStrategy::Auto;
  params.reuse_factorisation = ls->get<bool>("reuse_factorisation");
  params.krylov_tolerance = ls->get<double>("krylov_tolerance");
  params.krylov_max_iterations = ls->get<int>("krylov_max_iterations");
  params.krylov_refactor_iterations = ls->get<int>("krylov_refactor_iterations");
  params.adaptive_refactorisation = ls->get<bool>("adaptive_refactorisation");
}

// Nitsche parameters: the coupler's gamma_N1 / gamma_N2 (setup); the scene's
// interface.penalty / interface.symmetry are used when the setup gives no penalty
// (standalone runs). Returns fluid.interface.groups.
std::vector<std::string> read_nitsche(const schema::Reader& section, const FluidSetup& setup, FlowParameters& params) {
  params.nitsche_penalty = setup.nitsche_penalty;
  params.nitsche_symmetry = setup.nitsche_symmetry;
  const auto iface = section.optional_child("interface");
  if (!iface) return {};
  auto groups = string_list(*iface, "groups");
  const double penalty = iface->get_or<double>("penalty", setup.nitsche_penalty);
  const double symmetry = iface->get_or<double>("symmetry", setup.nitsche_symmetry);
  if (setup.nitsche_penalty == 0) {
    params.nitsche_penalty = penalty;
    params.nitsche_symmetry = symmetry;
  } else if (penalty != setup.nitsche_penalty || symmetry != setup.nitsche_symmetry) {
    fsi::logger("fluid")->warn(
        "fluid.interface.penalty/symmetry ({}, {}) differ from the coupler's gamma_N1/gamma_N2 "
        "({}, {}); using the coupler's",
        penalty, symmetry, setup.nitsche_penalty, setup.nitsche_symmetry);
  }
  if (params.nitsche_penalty < 0) iface->fail("penalty", "gamma_N1 must be >= 0");
  params.penalty_on_step_start = iface->get<std::string>("penalty_geometry") == "step_start";
  if (params.nitsche_symmetry != 1 && params.nitsche_symmetry != -1)
    iface->fail("symmetry", "gamma_N2 must be +1 or -1");
  return groups;
}

// The interface the coupler sees: the solver's interface nodes at their reference positions,
// with its segments (2D) or 6-node faces (3D).
template <int Dim>
InterfaceMeshData interface_of(const BasicFlowSolver<Dim>& solver) {
  InterfaceMeshData data;
  const auto& nodes = solver.interface_nodes();
  if (nodes.empty()) return data;  // a fluid alone
  data.dimension = Dim;
  data.coordinates.resize(static_cast<Eigen::Index>(nodes.size()), Dim);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    data.node_ids.push_back(nodes[i]);
    data.coordinates.row(static_cast<Eigen::Index>(i)) = solver.mesh().nodes.row(nodes[i]);
  }
  if constexpr (Dim == 3) {
    for (const auto& f : solver.interface_faces()) data.faces.push_back({std::vector<int>(f.begin(), f.end())});
  } else {
    const auto& seg = solver.interface_segments();
    for (Eigen::Index s = 0; s < seg.rows(); ++s) data.segments.push_back({seg(s, 0), seg(s, 1)});
  }
  return data;
}

// The loads of the last solve (f_sigma, f_v, M_f) on the interface.
template <int Dim>
FluidLoads loads_of(const BasicFlowSolver<Dim>& solver) {
  FluidLoads loads;
  loads.traction_force = solver.interface_traction();
  loads.velocity_integral = solver.interface_velocity_integral();
  loads.interface_mass = solver.interface_mass();
  return loads;
}

// A fluid.pressures entry: p from start_time to end_time (inclusive), 0 outside.
std::function<double(double)> pressure_function(const schema::Reader& entry) {
  const double p = entry.get<double>("pressure"), start = entry.get<double>("start_time");
  const double end = entry.get_or<double>("end_time", std::numeric_limits<double>::infinity());
  if (!(end >= start)) entry.fail("end_time", "end_time must not be before start_time");
  // (with a margin of round-off: t_n = n dt summed may land a hair after a step's end time)
  const double eps = 1e-9 * (std::abs(end) < 1e300 ? std::max(std::abs(end), 1e-6) : 0.0);
  return [=](double t) { return t >= start - eps && t <= end + eps ? p : 0.0; };
}

const char* scheme_name(TimeScheme scheme) {
  return scheme == TimeScheme::Steady ? "steady" : scheme == TimeScheme::BDF1 ? "bdf1" : "bdf2";
}

// --- boundary conditions ---

// The time factor of an inflow entry, 2D and 3D: the ramp 0.5 (1 - cos(pi t / ramp_time)) up to
// ramp_time, times pulsation {mean, amplitude, frequency}'s mean + amplitude sin(2 pi f t).
std::function<double(double)> inflow_time_factor(const schema::Reader& inflow) {
  const double ramp = inflow.get<double>("ramp_time");
  double pulse_mean = 1.0, pulse_amplitude = 0.0, pulse_frequency = 0.0;
  if (auto pulse = inflow.optional_child("pulsation")) {
    pulse_mean = pulse->get<double>("mean");
    pulse_amplitude = pulse->get<double>("amplitude");
    pulse_frequency = pulse->get<double>("frequency");
  }
  return [=](double t) {
    return ((ramp > 0 && t < ramp) ? 0.5 * (1 - std::cos(M_PI * t / ramp)) : 1.0) *
           (pulse_mean + pulse_amplitude * std::sin(2 * M_PI * pulse_frequency * t));
  };
}

// The velocity of an inflow entry on `group`: a parabolic or uniform profile along the
// group's extent (or profile_extent), optionally ramped and pulsating.
VelocityFunction inflow_velocity(const schema::Reader& inflow, const FluidMesh& mesh, const std::string& group) {
  const auto profile = inflow.get<std::string>("profile");
  double umax = 0;
  if (inflow.has("max_velocity"))
    umax = inflow.get<double>("max_velocity");
  else if (inflow.has("mean_velocity"))
    umax = (profile == "parabolic" ? 1.5 : 1.0) * inflow.get<double>("mean_velocity");
  else
    inflow.fail("max_velocity", "give max_velocity or mean_velocity");
  const Eigen::Vector2d direction = vector2(inflow, "direction").normalized();
  // Extent of the inlet along its tangent.
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = Eigen::Vector2d::Constant(-1e300);
  for (int i : mesh.boundary_nodes({group})) {
    lo = lo.cwiseMin(mesh.nodes.row(i).transpose());
    hi = hi.cwiseMax(mesh.nodes.row(i).transpose());
  }
  // The profile may span more than the group (a half channel with a symmetry line):
  // profile_extent: [[x0, y0], [x1, y1]] are the ends of the full profile.
  if (inflow.has("profile_extent")) {
    const auto ends = inflow.get<std::vector<std::vector<double>>>("profile_extent");
    if (ends.size() != 2 || ends[0].size() != 2 || ends[1].size() != 2)
      inflow.fail("profile_extent", "must be [[x0, y0], [x1, y1]]");
    lo = Eigen::Vector2d(ends[0][0], ends[0][1]);
    hi = Eigen::Vector2d(ends[1][0], ends[1][1]);
    if ((hi - lo).norm() <= 0) inflow.fail("profile_extent", "has zero length");
  }
  const Eigen::Vector2d tangent = (hi - lo).normalized();
  const double width = (hi - lo).norm();
  const auto time_factor = inflow_time_factor(inflow);
  std::function<double(double)> shape;
  if (profile == "parabolic")
    shape = [](double s) { return 4 * s * (1 - s); };
  else
    shape = [](double) { return 1.0; };
  return [=](const Eigen::Vector2d& x, double t) -> Eigen::Vector2d {
    const double s = std::clamp((x - lo).dot(tangent) / width, 0.0, 1.0);
    return umax * time_factor(t) * shape(s) * direction;
  };
}

}  // namespace

// The start of an open waveform window: the accepted state the window's substeps start from.
struct NavierStokesFluid::WindowStart {
  FlowSolver::History flow;
  FlowSolver3::History flow3;
  std::shared_ptr<const MeshMotion::Snapshot> motion;
  std::shared_ptr<const MeshMotion3::Snapshot> motion3;
  Eigen::VectorXd last_interface_displacement;
  StepReport report;
};

NavierStokesFluid::NavierStokesFluid() = default;
NavierStokesFluid::~NavierStokesFluid() = default;

void NavierStokesFluid::configure(const ConfigSection& fluid_section, const FluidSetup& setup) {
  const schema::Reader section(fluid_section, navier_stokes_keys());
  setup_ = setup;
  element_ = section.get<std::string>("element");
  if (section.get<std::string>("dimension") == "3") return configure3(section);
  const bool taylor_hood = element_ == "p2p1";
  const auto mesh_section = section.child("mesh");
  const auto msh = mesh_file(mesh_section, taylor_hood ? 2 : 1);
  FluidMesh mesh = read_mesh(mesh_section, msh, taylor_hood);
  FlowParameters params;
  read_physics(section, taylor_hood, params);
  if (params.backflow_beta > 0)
    section.fail("backflow_stabilisation", "is 3D only (fluid.dimension: 3); the 2D fluid has no backflow term");
  read_stabilisation(section, taylor_hood, params.stabilisation);
  read_linear_solver(section, taylor_hood, 2, params);
  const auto interface_groups = read_nitsche(section, setup, params);
  read_remesh(section, !interface_groups.empty());
  if (remesh_.enabled || !remesh_.at_steps.empty()) original_mesh_ = mesh;  // a checkpoint before the first remesh
  solver_ = std::make_unique<FlowSolver>(std::move(mesh), params, element_);
  watch(*solver_);
  const auto& fluid_mesh = solver_->mesh();

  const auto fixed_groups = add_boundary_conditions(section, msh.string());
  for (const auto& g : fluid_mesh.boundaries)
    if (std::find(fixed_groups.begin(), fixed_groups.end(), g.first) == fixed_groups.end() &&
        std::find(interface_groups.begin(), interface_groups.end(), g.first) == interface_groups.end())
      fsi::logger("fluid")->warn("boundary group '{}' has no condition: it is a do-nothing boundary", g.first);
  if (!interface_groups.empty()) configure_mesh_motion(section, interface_groups, fixed_groups);
  configure_output(section, params.density);
  if (section.has("initial_state")) load_initial_state(section.path("initial_state"));

  fsi::logger("fluid")->info(
      "fluid: {} ({}), {} nodes, {} triangles, {} unknowns, scheme {}, {}, {} interface nodes, "
      "mesh {}",
      element_, taylor_hood ? "Taylor-Hood" : "SUPG/PSPG", fluid_mesh.node_count(), fluid_mesh.triangle_count(),
      solver_->dofs(), scheme_name(params.scheme), params.newton ? "newton" : "picard",
      solver_->interface_nodes().size(), msh.string());
  start_ = last_log_ = std::chrono::steady_clock::now();
}

// fluid.dimension 3: tetrahedra, Taylor-Hood P2/P1 through the same FlowSolver (BasicFlowSolver<3>).
// Inflow profiles: uniform, or parabolic in both directions across the inlet's bounding box
// (DFG 3D: 16 U y z (H - y)(H - z) / H^4); walls; outlets; symmetry planes; force and pressure probes.
void NavierStokesFluid::configure3(const schema::Reader& section) {
  if (element_ != "p2p1") section.fail("element", "the 3D fluid is Taylor-Hood: set fluid.element: p2p1");
  const auto mesh_section = section.child("mesh");
  const auto msh = mesh_file(mesh_section, 2, 3);
  TetMesh mesh;
  try {
    mesh = TetMesh::from_gmsh(read_gmsh(msh), mesh_section.get_or<std::vector<std::string>>("domain", {}));
  } catch (const std::exception& e) {
    mesh_section.fail(mesh_section.has("file") ? "file" : "geo", e.what());
  }
  FlowParameters params;
  read_physics(section, true, params);
  read_stabilisation(section, true, params.stabilisation);
  if (params.stabilisation.supg) section.fail("stabilisation", "the 3D fluid has no SUPG (grad-div only)");
  read_linear_solver(section, true, 3, params);
  const auto interface_groups = read_nitsche(section, setup_, params);
  solver3_ = std::make_unique<FlowSolver3>(std::move(mesh), params, element_);
  const auto& m = solver3_->mesh();
  auto vec3 = [](const std::vector<double>& v, const schema::Reader& where, const std::string& key) {
    if (v.size() != 3) where.fail(key, fmt::format("a 3D scene needs [x, y, z], got {} numbers", v.size()));
    return Eigen::Vector3d(v[0], v[1], v[2]);
  };
  for (const auto& inflow : section.list("inflow")) {
    const auto group = inflow.get<std::string>("group");
    if (!m.has_boundary(group)) inflow.fail("group", "no boundary group '" + group + "' in " + msh.string());
    const Eigen::Vector3d direction =
        vec3(inflow.get<std::vector<double>>("direction"), inflow, "direction").normalized();
    const bool parabolic = inflow.get<std::string>("profile") == "parabolic";
    const double umax = inflow.has("max_velocity") ? inflow.get<double>("max_velocity")
                                                   : (parabolic ? 2.25 : 1.0) * inflow.get<double>("mean_velocity");
    const auto time_factor = inflow_time_factor(inflow);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (int n : m.boundary_nodes({group})) {
      lo = lo.cwiseMin(m.nodes.row(n).transpose());
      hi = hi.cwiseMax(m.nodes.row(n).transpose());
    }
    solver3_->add_dirichlet(group, [=](const Eigen::Vector3d& x, double t) -> Eigen::Vector3d {
      double shape = 1;
      if (parabolic)
        for (int c = 0; c < 3; ++c)
          if (hi(c) - lo(c) > 1e-12 * (hi - lo).norm()) {
            const double s = std::clamp((x(c) - lo(c)) / (hi(c) - lo(c)), 0.0, 1.0);
            shape *= 4 * s * (1 - s);
          }
      return umax * time_factor(t) * shape * direction;
    });
  }
  for (const auto& g : string_list(section, "walls")) {
    if (!m.has_boundary(g)) section.fail("walls", "no boundary group '" + g + "' in " + msh.string());
    solver3_->add_dirichlet(g, [](const Eigen::Vector3d&, double) { return Eigen::Vector3d::Zero(); });
  }
  for (const auto& g : string_list(section, "symmetry")) {
    if (!m.has_boundary(g)) section.fail("symmetry", "no boundary group '" + g + "' in " + msh.string());
    solver3_->add_symmetry(g);
  }
  for (const auto& g : string_list(section, "outlet")) {
    if (!m.has_boundary(g)) section.fail("outlet", "no boundary group '" + g + "' in " + msh.string());
    if (params.backflow_beta > 0) solver3_->add_open_boundary(g);
  }
  if (section.list("moving_walls").size() > 0) section.fail("moving_walls", "not in 3D yet");
  for (const auto& entry : section.list("pressures")) {
    const auto g = entry.get<std::string>("group");
    if (!m.has_boundary(g)) entry.fail("group", "no boundary group '" + g + "' in " + msh.string());
    solver3_->add_pressure(g, pressure_function(entry));
  }
  if (!interface_groups.empty()) {
    const auto iface = section.child("interface");
    for (const auto& g : interface_groups)
      if (!m.has_boundary(g)) iface.fail("groups", "no boundary group '" + g + "' in " + msh.string());
    interface_groups_ = interface_groups;
    solver3_->set_interface(interface_groups);
    std::vector<std::string> fixed;
    for (const auto& inflow : section.list("inflow")) fixed.push_back(inflow.get<std::string>("group"));
    for (const char* key : {"walls", "symmetry", "outlet"})
      for (const auto& g : string_list(section, key)) fixed.push_back(g);
    for (const auto& entry : section.list("pressures")) fixed.push_back(entry.get<std::string>("group"));
    fixed_groups_ = fixed;
    configure_mesh_motion3(iface);
  }
  if (auto pr = section.optional_child("pressure_reference"))
    solver3_->set_pressure_reference(vec3(pr->get<std::vector<double>>("point"), *pr, "point"),
                                     [v = pr->get<double>("value")](double) { return v; });
  for (const auto& f : section.list("forces")) {
    ForceProbe probe;
    probe.name = f.get<std::string>("name");
    probe.groups = f.get<std::vector<std::string>>("groups");
    for (const auto& g : probe.groups)
      if (!m.has_boundary(g)) f.fail("groups", "no boundary group '" + g + "'");
    if (f.has("reference_velocity")) {
      const double u = f.get<double>("reference_velocity"), l = f.get<double>("reference_length");
      probe.coefficient_scale = 2.0 / (params.density * u * u * l);  // DFG 3D: l = D H (an area)
    }
    forces_.push_back(probe);
  }
  (void)section.declared("pressure_probes");
  (void)section.declared("pressure_differences");
  if (auto pp = section.section().optional_child("pressure_probes"))
    for (const auto& k : pp->keys()) {
      const auto v = pp->get<std::vector<double>>(k);
      if (v.size() != 3) pp->fail(k, fmt::format("a 3D scene needs [x, y, z], got {} numbers", v.size()));
      pressure_probes3_.push_back({k, Eigen::Vector3d(v[0], v[1], v[2])});
    }
  if (auto pd = section.section().optional_child("pressure_differences"))
    for (const auto& k : pd->keys()) {
      const auto pair = pd->get<std::vector<std::string>>(k);
      for (const auto& p : pair)
        if (std::none_of(pressure_probes3_.begin(), pressure_probes3_.end(),
                         [&](const auto& q) { return q.first == p; }))
          pd->fail(k, "unknown pressure probe '" + p + "'");
      pressure_differences_.push_back({k, {pair[0], pair[1]}});
    }
  fsi::logger("fluid")->info(
      "fluid: 3D p2p1 (Taylor-Hood), {} nodes, {} tetrahedra, {} unknowns, scheme {}, {}, {} interface nodes, mesh {}",
      m.node_count(), m.cell_count(), solver3_->dofs(), scheme_name(params.scheme), params.newton ? "newton" : "picard",
      solver3_->interface_nodes().size(), msh.string());
  configure_vtk(section);
  start_ = last_log_ = std::chrono::steady_clock::now();
}

std::map<std::string, double> NavierStokesFluid::probes3() {
  std::map<std::string, double> probes;
  for (const auto& f : forces_) {
    const Eigen::Vector3d force = solver3_->force(f.groups);
    const std::string prefix = f.name.empty() ? "" : f.name + "_";
    probes[prefix + "drag"] = force.x();
    probes[prefix + "lift"] = force.y();
    probes[prefix + "side"] = force.z();
    if (f.coefficient_scale > 0) {
      probes[prefix + "cd"] = f.coefficient_scale * force.x();
      probes[prefix + "cl"] = f.coefficient_scale * force.y();
    }
  }
  for (const auto& [name, point] : pressure_probes3_) probes[name] = solver3_->pressure_at(point);
  for (const auto& [name, pair] : pressure_differences_) probes[name] = probes.at(pair.first) - probes.at(pair.second);
  probes["nonlinear_iterations"] = last_report_.iterations;
  probes["nonlinear_change"] = last_report_.change;
  if (motion3_) {  // the moving mesh's quality (fsi/fluid/mesh_quality.hpp)
    const TetMeshQuality q = mesh_quality(solver3_->mesh(), solver3_->accepted_positions());
    probes["mesh_min_scaled_jacobian"] = q.min_scaled_jacobian;
    probes["mesh_min_curved_jacobian"] = q.min_curved_jacobian;
  }
  probes["factorisations"] = factorisations_;
  probes["linear_iterations"] = linear_iterations_;  // Krylov iterations so far (3D only: 2D outputs unchanged)
  return probes;
}

// fluid.inflow, walls, moving_walls, symmetry, outlet and pressure_reference on the solver.
// Returns the groups with a condition (the mesh motion holds them fixed).
std::vector<std::string> NavierStokesFluid::add_boundary_conditions(const schema::Reader& section,
                                                                    const std::string& msh) {
  const auto& mesh = solver_->mesh();
  std::vector<std::string> fixed;
  // Each condition is kept, to set it on the solver of a new mesh (remeshing).
  struct Recorder {
    NavierStokesFluid& self;
    void add_dirichlet(const std::string& g, VelocityFunction f) {
      self.conditions_.push_back([g, f](FlowSolver& s) { s.add_dirichlet(g, f); });
    }
    void add_symmetry(const std::string& g) {
      self.conditions_.push_back([g](FlowSolver& s) { s.add_symmetry(g); });
    }
    void set_pressure_reference(const Eigen::Vector2d& p, std::function<double(double)> v) {
      self.conditions_.push_back([p, v](FlowSolver& s) { s.set_pressure_reference(p, v); });
    }
    void add_pressure(const std::string& g, std::function<double(double)> p) {
      self.conditions_.push_back([g, p](FlowSolver& s) { s.add_pressure(g, p); });
    }
  } solver{*this};
  conditions_.clear();
  for (const auto& inflow : section.list("inflow")) {
    const auto group = inflow.get<std::string>("group");
    fixed.push_back(group);
    if (!mesh.has_boundary(group)) inflow.fail("group", "no boundary group '" + group + "' in " + msh);
    solver.add_dirichlet(group, inflow_velocity(inflow, mesh, group));
  }
  for (const auto& g : string_list(section, "walls")) {
    if (!mesh.has_boundary(g)) section.fail("walls", "no boundary group '" + g + "' in " + msh);
    solver.add_dirichlet(g, [](const Eigen::Vector2d&, double) { return Eigen::Vector2d::Zero(); });
    fixed.push_back(g);
  }
  for (const auto& mw : section.list("moving_walls")) {
    const auto g = mw.get<std::string>("group");
    if (!mesh.has_boundary(g)) mw.fail("group", "no boundary group '" + g + "' in " + msh);
    const Eigen::Vector2d v = vector2(mw, "velocity");
    solver.add_dirichlet(g, [v](const Eigen::Vector2d&, double) { return v; });
    fixed.push_back(g);
  }
  for (const auto& g : string_list(section, "symmetry")) {
    if (!mesh.has_boundary(g)) section.fail("symmetry", "no boundary group '" + g + "' in " + msh);
    solver.add_symmetry(g);
    fixed.push_back(g);
  }
  for (const auto& g : string_list(section, "outlet")) {
    if (!mesh.has_boundary(g)) section.fail("outlet", "no boundary group '" + g + "' in " + msh);
    fixed.push_back(g);
  }
  for (const auto& entry : section.list("pressures")) {
    const auto g = entry.get<std::string>("group");
    if (!mesh.has_boundary(g)) entry.fail("group", "no boundary group '" + g + "' in " + msh);
    if (element_ != "p2p1") entry.fail("group", "pressure boundaries need fluid.element: p2p1");
    solver.add_pressure(g, pressure_function(entry));
    fixed.push_back(g);
  }
  if (auto pr = section.optional_child("pressure_reference"))
    solver.set_pressure_reference(vector2(*pr, "point"), [v = pr->get<double>("value")](double) { return v; });
  for (const auto& c : conditions_) c(*solver_);
  return fixed;
}

// The Nitsche interface and the mesh motion (fluid.interface): the extension of the interface
// displacement into the mesh, the groups with conditions held fixed.
void NavierStokesFluid::configure_mesh_motion(const schema::Reader& section, const std::vector<std::string>& groups,
                                              const std::vector<std::string>& fixed_groups) {
  const auto& fluid_mesh = solver_->mesh();
  const auto iface = section.child("interface");
  for (const auto& g : groups)
    if (!fluid_mesh.has_boundary(g)) iface.fail("groups", "no boundary group '" + g + "'");
  interface_groups_ = groups;
  fixed_groups_ = fixed_groups;
  solver_->set_interface(groups);
  MeshMotionOptions& motion = motion_options_;
  motion.stiffening = iface.get<double>("mesh_stiffening");
  if (iface.get<std::string>("mesh_motion") == "elastic") motion.method = MeshMotionOptions::Method::Elastic;
  motion.incremental = iface.get<bool>("mesh_incremental");
  // P2 meshes: the interface midpoints take the solid's displacement (curved interface
  // edges follow the solid); the extension runs either on the vertices (default: interior
  // midpoints move with the mean of their edge's vertices, edges stay straight inside) or on
  // the 4-triangle refinement of every element (every node extended; 4x the unknowns).
  const auto on = fluid_mesh.quadratic() ? iface.get<std::string>("mesh_motion_nodes") : "all";
  motion_on_vertices_ = fluid_mesh.quadratic() && on == "vertices";
  build_mesh_motion();
}

// The extension on the solver's current mesh (its reference positions), from the options read.
void NavierStokesFluid::build_mesh_motion() {
  const auto& fluid_mesh = solver_->mesh();
  const auto& fixed_groups = fixed_groups_;
  std::vector<int> moving = solver_->interface_nodes(), fixed = fluid_mesh.boundary_nodes(fixed_groups);
  if (motion_on_vertices_) {
    const int nv = fluid_mesh.vertices();
    motion_mesh_.nodes = fluid_mesh.nodes.topRows(nv);
    motion_mesh_.triangles = fluid_mesh.triangles;
    motion_mesh_.boundaries = fluid_mesh.boundaries;
    motion_vertex_index_.clear();
    std::vector<int> vertex_nodes;
    for (std::size_t i = 0; i < moving.size(); ++i)
      if (moving[i] < nv) {
        motion_vertex_index_.push_back(static_cast<int>(i));
        vertex_nodes.push_back(moving[i]);
      }
    moving = vertex_nodes;
    fixed.erase(std::remove_if(fixed.begin(), fixed.end(), [nv](int n) { return n >= nv; }), fixed.end());
  } else {
    motion_mesh_ = fluid_mesh.linear_refinement();
  }
  motion_ =
      std::make_unique<MeshMotion>(motion_mesh_, moving, fixed, motion_options_);  // keeps a pointer to motion_mesh_
}

// Force probes, pressure probes and differences, VTK (fluid.forces, pressure_probes,
// pressure_differences, output).
void NavierStokesFluid::configure_output(const schema::Reader& section, double density) {
  const auto& fluid_mesh = solver_->mesh();
  for (const auto& f : section.list("forces")) {
    ForceProbe probe;
    probe.name = f.get<std::string>("name");
    probe.groups = f.get<std::vector<std::string>>("groups");
    for (const auto& g : probe.groups)
      if (!fluid_mesh.has_boundary(g)) f.fail("groups", "no boundary group '" + g + "'");
    if (f.has("reference_velocity")) {
      const double u = f.get<double>("reference_velocity"), l = f.get<double>("reference_length");
      probe.coefficient_scale = 2.0 / (density * u * u * l);
    }
    forces_.push_back(probe);
  }
  (void)section.declared("pressure_probes");
  (void)section.declared("pressure_differences");
  if (auto pp = section.section().optional_child("pressure_probes"))
    for (const auto& k : pp->keys()) pressure_probes_.push_back({k, named_point(*pp, k)});
  if (auto pd = section.section().optional_child("pressure_differences"))
    for (const auto& k : pd->keys()) {
      const auto pair = pd->get<std::vector<std::string>>(k);
      if (pair.size() != 2) pd->fail(k, "must name two pressure probes [high, low]");
      for (const auto& p : pair)
        if (std::none_of(pressure_probes_.begin(), pressure_probes_.end(), [&](const auto& q) { return q.first == p; }))
          pd->fail(k, "unknown pressure probe '" + p + "'");
      pressure_differences_.push_back({k, {pair[0], pair[1]}});
    }
  configure_vtk(section);
}

// VTK whenever the run asks (time.output_every), unless output.vtk_every says otherwise:
// N > 0 = only at steps that are multiples of N, 0 = never. Both dimensions (flow_vtk.hpp).
void NavierStokesFluid::configure_vtk(const schema::Reader& section) {
  if (auto out = section.optional_child("output")) {
    vtk_every_ = out->get_or<int>("vtk_every", -1);
  }
  if (vtk_every_ != 0 && !setup_.output_dir.empty()) vtk_ = PvdSeries(setup_.output_dir, "fluid", setup_.vtk_format);
}

// fluid.remesh: {enabled (default: with an interface), min_quality, min_curved_jacobian, at_steps}.
void NavierStokesFluid::read_remesh(const schema::Reader& section, bool moving) {
  const auto rm = section.child_or_defaults("remesh");
  remesh_.enabled = rm.get_or<bool>("enabled", moving);
  remesh_.min_quality = rm.get<double>("min_quality");
  remesh_.min_curved_jacobian = rm.get<double>("min_curved_jacobian");
  remesh_.at_steps = rm.get_or<std::vector<int>>("at_steps", {});
  if (remesh_.enabled && !moving)
    rm.fail("enabled", "the quality trigger needs a moving mesh (fluid.interface.groups)");
}

// Replaces the solver by one on a new mesh of the current (accepted) domain, keeping every
// boundary node (remesh.hpp), with the state interpolated (FlowSolver::transfer_state); the
// mesh motion restarts from the new mesh, whose reference positions are the current ones.
void NavierStokesFluid::remesh(const StepInfo& info, const std::string& why) {
  const auto t0 = std::chrono::steady_clock::now();
  const FlowSolver& old = *solver_;
  const MeshQuality before = mesh_quality(old.mesh(), old.accepted_positions());
  if (remesh_size_.size() == 0) remesh_size_ = reference_sizes(old.mesh());
  RemeshResult r = fluid::remesh(old.mesh(), old.accepted_positions(), remesh_size_);
  auto fresh = make_solver(std::move(r.mesh), old.parameters());
  const auto &oi = old.interface_nodes(), &ni = fresh->interface_nodes();
  bool same = oi.size() == ni.size();
  for (std::size_t k = 0; same && k < ni.size(); ++k) same = r.old_node[static_cast<std::size_t>(ni[k])] == oi[k];
  if (!same)
    throw SolverError(
        fmt::format("step {}: remeshing changed the interface nodes ({} -> {}); the coupler's mapping "
                    "would not fit",
                    info.step, oi.size(), ni.size()));
  const TransferReport transfer = fresh->transfer_state(old, r.old_node);
  if (motion_ && accepted_interface_displacement_.size() > 0) {  // the mesh is remeshed as accepted
    if (remesh_offset_.size() != accepted_interface_displacement_.size())
      remesh_offset_ = Eigen::VectorXd::Zero(accepted_interface_displacement_.size());
    remesh_offset_ += accepted_interface_displacement_;
    accepted_interface_displacement_.setZero();
    last_interface_displacement_.setZero();
  }
  const int old_nodes = old.mesh().node_count();
  solver_ = std::move(fresh);
  remesh_size_ = std::move(r.vertex_size);
  if (motion_) build_mesh_motion();
  const MeshQuality after = mesh_quality(solver_->mesh(), solver_->mesh().nodes);
  remesh_quality_ = std::min(after.min_scaled_jacobian,
                             solver_->mesh().quadratic()
                                 ? after.min_curved_jacobian / remesh_.min_curved_jacobian * remesh_.min_quality
                                 : 1.0);
  ++remeshes_;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  remesh_seconds_ += seconds;
  fsi::logger("fluid")->info(
      "fluid: remesh {} at step {} (t = {:.6g}; {}): {} -> {} nodes, scaled Jacobian {:.3g} -> "
      "{:.3g}, max angle {:.1f} -> {:.1f} deg; {} of {} points outside the old mesh (by <= "
      "{:.2e}); {:.3f} s ({:.3f} s in gmsh)",
      remeshes_, info.step, info.time, why, old_nodes, solver_->mesh().node_count(), before.min_scaled_jacobian,
      after.min_scaled_jacobian, before.max_angle_deg, after.max_angle_deg, transfer.outside, transfer.points,
      transfer.max_distance, seconds, r.seconds);
}

// The solver's nonlinear iterations reach whoever runs this model (IterationReporting).
void NavierStokesFluid::watch(FlowSolver& solver) const {
  solver.set_iteration_observer([this](int iteration, double change) {
    report_iteration(fmt::format("nonlinear iteration {} change {:.2e}", iteration, change));
  });
}

// A solver on `mesh` with the scene's conditions and interface.
std::unique_ptr<FlowSolver> NavierStokesFluid::make_solver(FluidMesh mesh, const FlowParameters& params) const {
  auto s = std::make_unique<FlowSolver>(std::move(mesh), params, element_);
  watch(*s);
  for (const auto& c : conditions_) c(*s);
  if (!interface_groups_.empty()) s->set_interface(interface_groups_);
  return s;
}

namespace {
Eigen::VectorXd index_vector(const int* data, Eigen::Index n) {
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = data[i];
  return v;
}
template <class M>
void index_matrix(const StateArchive& state, const std::string& name, M& m, Eigen::Index cols) {
  const Eigen::VectorXd v = state.vector(name);
  if (v.size() % cols != 0)
    throw StateError(fmt::format("entry '{}' has {} values, not a multiple of {}", name, v.size(), cols));
  m.resize(v.size() / cols, cols);
  for (Eigen::Index i = 0; i < v.size(); ++i) m.data()[i] = static_cast<int>(v(i));
}
}  // namespace

// Checkpoints hold the current mesh (the scene's until a remesh): remesh.count, remesh.offset (the interface
// displacement at the last remesh), remesh.quality, remesh.size (the target size per vertex), remesh.nodes
// (column-major), remesh.triangles, remesh.edge_nodes (row-major), remesh.vertex_count, remesh.groups (names, one a
// line) and per group remesh.boundary.NAME and remesh.midpoints.NAME.
void NavierStokesFluid::save_remeshed(StateArchive& state) const {
  const auto& m = solver_->mesh();
  state.put("remesh.count", static_cast<std::int64_t>(remeshes_));
  if (remesh_retries_ > 0) state.put("remesh.retries", static_cast<std::int64_t>(remesh_retries_));
  state.put("remesh.offset", remesh_offset_);
  state.put("remesh.quality", remesh_quality_);
  state.put("remesh.size", remesh_size_);
  state.put("remesh.nodes", Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(m.nodes.data(), m.nodes.size())));
  state.put("remesh.triangles", index_vector(m.triangles.data(), m.triangles.size()));
  state.put("remesh.edge_nodes", index_vector(m.edge_nodes.data(), m.edge_nodes.size()));
  state.put("remesh.vertex_count", static_cast<std::int64_t>(m.vertex_count));
  std::string groups;
  for (const auto& [name, seg] : m.boundaries) {
    groups += name + "\n";
    state.put("remesh.boundary." + name, index_vector(seg.data(), seg.size()));
    if (const auto it = m.boundary_midpoints.find(name); it != m.boundary_midpoints.end())
      state.put("remesh.midpoints." + name, index_vector(it->second.data(), it->second.size()));
  }
  state.put("remesh.groups", groups);
}

// The mesh of a checkpoint: a remeshed one (remesh.*), or the scene's when this model has
// remeshed since; the solver and the mesh motion are rebuilt on it before their states load.
void NavierStokesFluid::load_remeshed(const StateArchive& state) {
  const std::int64_t count = state.has("remesh.count") ? state.integer("remesh.count") : 0;
  if (count == 0 && remeshes_ == 0) return;
  FluidMesh mesh;
  if (count > 0) {
    mesh = mesh_from_state(state);
  } else {
    if (original_mesh_.node_count() == 0) throw std::logic_error("NavierStokesFluid: no scene mesh kept");
    mesh = original_mesh_;
  }
  solver_ = make_solver(std::move(mesh), solver_->parameters());
  if (motion_) build_mesh_motion();
  remeshes_ = static_cast<int>(count);
  remesh_retries_ = state.has("remesh.retries") ? static_cast<int>(state.integer("remesh.retries")) : 0;
  remesh_offset_ = count > 0 ? state.vector("remesh.offset") : Eigen::VectorXd();
  remesh_quality_ = count > 0 ? state.real("remesh.quality") : 1.0;
  remesh_size_ = count > 0 ? state.vector("remesh.size") : Eigen::VectorXd();
}

// The mesh a checkpoint holds (remesh.*).
FluidMesh NavierStokesFluid::mesh_from_state(const StateArchive& state) {
  FluidMesh mesh;
  {
    const Eigen::VectorXd nodes = state.vector("remesh.nodes");
    mesh.nodes = Eigen::Map<const Eigen::MatrixX2d>(nodes.data(), nodes.size() / 2, 2);
    index_matrix(state, "remesh.triangles", mesh.triangles, 3);
    index_matrix(state, "remesh.edge_nodes", mesh.edge_nodes, 3);
    mesh.vertex_count = static_cast<int>(state.integer("remesh.vertex_count"));
    std::istringstream groups(state.text("remesh.groups"));
    for (std::string name; std::getline(groups, name);) {
      if (name.empty()) continue;
      index_matrix(state, "remesh.boundary." + name, mesh.boundaries[name], 2);
      if (mesh.quadratic()) {
        const Eigen::VectorXd mid = state.vector("remesh.midpoints." + name);
        mesh.boundary_midpoints[name] = mid.cast<int>();
      }
    }
  }
  return mesh;
}

// fluid.initial_state: a fluid.state of another run's checkpoint (fsi run --initial-state
// RUN_DIR finds the newest): its velocity and pressure, on its mesh where it was (another
// mesh, another element), interpolated onto this mesh (FlowSolver::transfer_state); the run
// starts from them with BDF1, a mesh at rest and zero interface velocity.
void NavierStokesFluid::load_initial_state(const std::filesystem::path& file) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string where = "fluid.initial_state: " + file.string();
  if (std::filesystem::is_directory(file))
    throw StateError(
        fmt::format("{} is a folder: give the fluid.state of one of its checkpoints "
                    "(checkpoints/step_N/fluid.state), or fsi run --initial-state RUN_DIR",
                    where));
  const auto state = StateArchive::parse(read_text(file), where);
  if (!state.has("remesh.nodes")) {
    const auto names = state.names();
    const bool fluid =
        std::any_of(names.begin(), names.end(), [](const std::string& n) { return n.rfind("flow.", 0) == 0; });
    if (!fluid) {
      std::string some;
      for (std::size_t i = 0; i < names.size() && i < 3; ++i) some += (i ? ", " : "") + names[i];
      throw StateError(
          fmt::format("{} is not a fluid's state (no 'flow.*' entries; it holds {}{}): give a "
                      "fluid.state of another run's checkpoint",
                      where, names.empty() ? "nothing" : some, names.size() > 3 ? ", ..." : ""));
    }
    throw StateError(fmt::format(
        "{}: the checkpoint holds no fluid mesh (written by an older build, before checkpoints held it)", where));
  }
  FlowSolver old(mesh_from_state(state), solver_->parameters(), state.text("flow.element"));
  if (state.vector("flow.interface_velocity").size() > 0) old.set_interface(interface_groups_);
  old.load_state(state, "flow.");
  const TransferReport r =
      solver_->transfer_state(old, std::vector<int>(static_cast<std::size_t>(solver_->mesh().node_count()), -1));
  solver_->restart_history();
  fsi::logger("fluid")->info(
      "fluid: initial state from {} ({} on {} nodes): {} of {} points outside its mesh (by <= "
      "{:.2e}); {:.3f} s",
      file.string(), state.text("flow.element"), old.mesh().node_count(), r.outside, r.points, r.max_distance,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

Eigen::VectorXd NavierStokesFluid::motion_input(const Eigen::VectorXd& interface_displacement) const {
  if (!motion_on_vertices_) return interface_displacement;
  Eigen::VectorXd d(2 * static_cast<Eigen::Index>(motion_vertex_index_.size()));
  for (std::size_t k = 0; k < motion_vertex_index_.size(); ++k)
    d.segment<2>(2 * static_cast<Eigen::Index>(k)) = interface_displacement.segment<2>(2 * motion_vertex_index_[k]);
  return d;
}

Eigen::MatrixX2d NavierStokesFluid::extend(const Eigen::VectorXd& interface_displacement) const {
  const Eigen::MatrixX2d vertex = motion_->extend(motion_input(interface_displacement));
  if (!motion_on_vertices_) return vertex;
  const auto& mesh = solver_->mesh();
  Eigen::MatrixX2d out(mesh.node_count(), 2);
  out.topRows(mesh.vertices()) = vertex;
  mesh.interpolate_midpoints(out);
  const auto& nodes = solver_->interface_nodes();
  for (std::size_t i = 0; i < nodes.size(); ++i)
    out.row(nodes[i]) = interface_displacement.segment<2>(2 * static_cast<Eigen::Index>(i)).transpose();
  return out;
}

// 3D: the mesh motion of the interface (fluid.interface's mesh_motion keys): MeshMotion3 on the
// 10-node tetrahedra (extended on the vertices; interface midpoints follow the interface,
// interior ones the mean of their edge), the groups with conditions held fixed.
void NavierStokesFluid::configure_mesh_motion3(const schema::Reader& iface) {
  MeshMotionOptions& motion = motion_options_;
  motion.stiffening = iface.get<double>("mesh_stiffening");
  if (iface.get<std::string>("mesh_motion") == "elastic") motion.method = MeshMotionOptions::Method::Elastic;
  motion.incremental = iface.get<bool>("mesh_incremental");
  if (iface.get<std::string>("mesh_motion_nodes") != "vertices")
    iface.fail("mesh_motion_nodes", "the 3D fluid extends the displacement on the vertices only");
  const auto& mesh = solver3_->mesh();
  motion3_ = std::make_unique<MeshMotion3>(mesh, solver3_->interface_nodes(), mesh.boundary_nodes(fixed_groups_),
                                           motion_options_);  // keeps a pointer to the solver's mesh
}

// 3D: every node's position for the interface displacement (3 per interface node).
Eigen::MatrixX3d NavierStokesFluid::positions3(const Eigen::VectorXd& interface_displacement) {
  if (!motion3_ || interface_displacement.size() == 0) return solver3_->mesh().nodes;
  last_interface_displacement_ = interface_displacement;
  return motion3_->positions(interface_displacement);
}

InterfaceMeshData NavierStokesFluid::interface() const {
  return solver3_ ? interface_of(*solver3_) : interface_of(*solver_);
}

FluidLoads NavierStokesFluid::initial_loads(const Eigen::VectorXd&, const Eigen::VectorXd&) {
  return solver3_ ? loads_of(*solver3_) : loads_of(*solver_);
}

// One solve on the current mesh, moved by the interface displacement (after a remesh measured
// from the mesh of the remesh).
void NavierStokesFluid::solve_on_mesh(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                                      const Eigen::VectorXd& interface_velocity, const RobinCondition* robin) {
  Eigen::MatrixX2d positions = solver_->mesh().nodes;
  if (motion_ && interface_displacement.size() > 0) {
    const Eigen::VectorXd d = remesh_offset_.size() == interface_displacement.size()
                                  ? Eigen::VectorXd(interface_displacement - remesh_offset_)
                                  : interface_displacement;
    positions += extend(d);
    last_interface_displacement_ = d;
  }
  last_report_ = robin ? solver_->solve_robin(info.time, info.dt, positions, *robin)
                       : solver_->solve(info.time, info.dt, positions, interface_velocity);
}

FluidLoads NavierStokesFluid::solve_step(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                                         const Eigen::VectorXd& interface_velocity) {
  if (window_) restore_window_start(), close_window();  // (a window left open: its start again)
  return solve(info, interface_displacement, interface_velocity, nullptr);
}

void NavierStokesFluid::hold_penalty_interface(bool hold) {
  if (solver3_) solver3_->hold_penalty_interface(hold);
  if (solver_) solver_->hold_penalty_interface(hold);
}

void NavierStokesFluid::close_window() {
  window_.reset();
  hold_penalty_interface(false);
}

bool NavierStokesFluid::supports_substeps() const {
  const FlowParameters* p = solver_ ? &solver_->parameters() : solver3_ ? &solver3_->parameters() : nullptr;
  return p && p->scheme != TimeScheme::Steady;
}

void NavierStokesFluid::restore_window_start() {
  const WindowStart& w = *window_;
  if (solver3_) {
    solver3_->set_history(w.flow3);
    if (motion3_) motion3_->restore(*w.motion3);
  } else {
    solver_->set_history(w.flow);
    if (motion_) motion_->restore(*w.motion);
  }
  last_interface_displacement_ = w.last_interface_displacement;
  last_report_ = w.report;
}

// A substep inside a window accepted as accept_step() does, without probes or remeshing.
void NavierStokesFluid::accept_substep() {
  if (solver3_) {
    solver3_->accept();
    if (motion3_ && last_interface_displacement_.size() > 0) motion3_->accept(last_interface_displacement_);
    return;
  }
  solver_->accept();
  if (motion_ && last_interface_displacement_.size() > 0) motion_->accept(motion_input(last_interface_displacement_));
}

// Substeps of h = dt / substeps; like FemSolid::solve_window. The window stays open (its start
// kept) until accept_step(), which accepts the last substep as a step is accepted.
FluidLoads NavierStokesFluid::solve_window(const StepInfo& info, const Waveform& displacement, const Waveform& velocity,
                                           int substeps) {
  if (!solver_ && !solver3_) throw SolverError("fluid: solve_window before configure");
  if (!supports_substeps()) return FluidModel::solve_window(info, displacement, velocity, substeps);  // (throws)
  if (window_) {
    restore_window_start();
  } else {
    auto w = std::make_unique<WindowStart>();
    if (solver3_) {
      w->flow3 = solver3_->history();
      if (motion3_) w->motion3 = motion3_->snapshot();
    } else {
      w->flow = solver_->history();
      if (motion_) w->motion = motion_->snapshot();
    }
    w->last_interface_displacement = last_interface_displacement_;
    w->report = last_report_;
    window_ = std::move(w);
    hold_penalty_interface(true);  // penalty_geometry step_start: the window's start, as the solid's M_G
  }
  const TimeScheme scheme = solver3_ ? solver3_->parameters().scheme : solver_->parameters().scheme;
  Waveform d = displacement, v = velocity;
  d.degree = v.degree = scheme == TimeScheme::BDF1 ? 1 : 2;
  const double h = info.dt / substeps, t0 = info.time - info.dt;
  FluidLoads out;
  Eigen::VectorXd traction, integral;
  int iterations = 0;
  in_window_ = true;
  try {
    for (int j = 1; j <= substeps; ++j) {
      if (j > 1) accept_substep();  // the last substep becomes the history of the next
      const StepInfo sub{substep_time(t0, info.dt, j, substeps), h, info.step, info.iteration};
      const FluidLoads loads = solve(sub, d.at(sub.time), v.at(sub.time), nullptr);
      iterations += loads.nonlinear_iterations;
      const Eigen::Index m = loads.traction_force.size();
      if (j == 1) traction.resize(m * substeps), integral.resize(m * substeps);
      traction.segment((j - 1) * m, m) = loads.traction_force;
      integral.segment((j - 1) * m, m) = loads.velocity_integral;
      if (j == substeps) out = loads;
    }
  } catch (...) {
    in_window_ = false;
    restore_window_start();
    throw;
  }
  in_window_ = false;
  out.traction_samples = std::move(traction);
  out.velocity_integral_samples = std::move(integral);
  out.nonlinear_iterations = iterations;
  return out;
}

FluidLoads NavierStokesFluid::solve_robin(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                                          const RobinCondition& robin) {
  if (!solver_) return FluidModel::solve_robin(info, interface_displacement, robin);  // (3D: throws)
  if (window_) restore_window_start(), close_window();
  return solve(info, interface_displacement, Eigen::VectorXd(), &robin);
}

FluidLoads NavierStokesFluid::solve(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                                    const Eigen::VectorXd& interface_velocity, const RobinCondition* robin) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto where = [&](const std::exception& e) {
    return fmt::format("step {} (t = {:.6g}, coupling iteration {}): {}", info.step, info.time, info.iteration,
                       e.what());
  };
  if (solver3_) {
    try {
      last_report_ = solver3_->solve(info.time, info.dt, positions3(interface_displacement), interface_velocity);
    } catch (const SolverError& e) {
      throw SolverError(where(e));
    }
    solve_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++solves_;
    factorisations_ += last_report_.factorisations;
    linear_iterations_ += last_report_.krylov_iterations;
    assembly_seconds_ += last_report_.assembly_seconds;
    factor_seconds_ += last_report_.factor_seconds;
    linear_solve_seconds_ += last_report_.solve_seconds;
    FluidLoads loads = loads_of(*solver3_);
    loads.nonlinear_iterations = last_report_.iterations;
    return loads;
  }
  try {
    try {
      solve_on_mesh(info, interface_displacement, interface_velocity, robin);
    } catch (const MeshTangled& e) {
      // The step's motion folded an element of a mesh that was valid at the step's start (the
      // quality check between steps came too late: one step moved the interface that far).
      // With remeshing on: remesh the step-start mesh once and solve this iteration again on
      // the new mesh; a second fold in the same step is an error.
      if (!remesh_.enabled || !motion_ || retried_step_ == info.step) throw;
      if (in_window_)
        throw SolverError(fmt::format(
            "{}; inside a waveform window (fluid.substeps > 1) a fold is not cured by remeshing the step-start mesh "
            "(remeshing happens between windows): a smaller time.dt, or fluid.substeps: 1",
            e.what()));
      fsi::logger("fluid")->warn("fluid: {}; remeshing the step-start mesh and solving again", where(e));
      retried_step_ = info.step;
      try {
        remesh(info, "the step's mesh motion inverted an element");
      } catch (const std::exception& r) {  // the fold stays the error, with why the cure failed
        throw SolverError(fmt::format("{}; remeshing the step-start mesh failed: {}", e.what(), r.what()));
      }
      ++remesh_retries_;
      solve_on_mesh(info, interface_displacement, interface_velocity, robin);
    }
  } catch (const SolverError& e) {
    throw SolverError(where(e));
  }
  solve_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++solves_;
  FluidLoads loads = loads_of(*solver_);
  loads.nonlinear_iterations = last_report_.iterations;
  factorisations_ += last_report_.factorisations;
  assembly_seconds_ += last_report_.assembly_seconds;
  factor_seconds_ += last_report_.factor_seconds;
  linear_solve_seconds_ += last_report_.solve_seconds;
  fsi::logger("fluid")->debug(
      "step {} t={:.5g}: {} iteration(s), change {:.2e}, assembly {:.3f}s, {} factorisation(s) "
      "{:.3f}s, {} BiCGSTAB iterations, solve {:.3f}s",
      info.step, info.time, last_report_.iterations, last_report_.change, last_report_.assembly_seconds,
      last_report_.factorisations, last_report_.factor_seconds, last_report_.krylov_iterations,
      last_report_.solve_seconds);
  return loads;
}

std::map<std::string, double> NavierStokesFluid::accept_step(const StepInfo& info) {
  close_window();  // an open window's end is the state accepted now
  if (solver3_) {
    solver3_->accept();
    if (motion3_ && last_interface_displacement_.size() > 0) motion3_->accept(last_interface_displacement_);
    accepted_interface_displacement_ = last_interface_displacement_;
    return probes3();
  }
  solver_->accept();
  if (motion_ && last_interface_displacement_.size() > 0) motion_->accept(motion_input(last_interface_displacement_));
  accepted_interface_displacement_ = last_interface_displacement_;
  std::map<std::string, double> probes;
  for (const auto& f : forces_) {
    const Eigen::Vector2d force = solver_->force(f.groups);
    const std::string prefix = f.name.empty() ? "" : f.name + "_";
    probes[prefix + "drag"] = force.x();
    probes[prefix + "lift"] = force.y();
    if (f.coefficient_scale > 0) {
      probes[prefix + "cd"] = f.coefficient_scale * force.x();
      probes[prefix + "cl"] = f.coefficient_scale * force.y();
    }
  }
  for (const auto& [name, point] : pressure_probes_) probes[name] = solver_->pressure_at(point);
  for (const auto& [name, pair] : pressure_differences_) probes[name] = probes.at(pair.first) - probes.at(pair.second);
  probes["nonlinear_iterations"] = last_report_.iterations;
  probes["nonlinear_change"] = last_report_.change;
  probes["factorisations"] = factorisations_;
  MeshQuality q;
  if (motion_) {  // the moving mesh's quality (fsi/fluid/mesh_quality.hpp)
    q = mesh_quality(solver_->mesh(), solver_->accepted_positions());
    probes["mesh_min_scaled_jacobian"] = q.min_scaled_jacobian;
    probes["mesh_max_angle"] = q.max_angle_deg;
    if (solver_->mesh().quadratic()) probes["mesh_min_curved_jacobian"] = q.min_curved_jacobian;
  }
  // Remeshing (after the probes: they are the step's, on the mesh it was solved on).
  if (remesh_.enabled || !remesh_.at_steps.empty()) {
    const bool forced =
        std::find(remesh_.at_steps.begin(), remesh_.at_steps.end(), info.step) != remesh_.at_steps.end();
    // Below the threshold, and below what the last remesh reached (a remesh that could not
    // reach the threshold, e.g. at a sharp boundary corner, is not repeated every step).
    const double worst = std::min(
        q.min_scaled_jacobian,
        solver_->mesh().quadratic() ? q.min_curved_jacobian / remesh_.min_curved_jacobian * remesh_.min_quality : 1.0);
    const bool poor = remesh_.enabled && motion_ && worst < remesh_.min_quality && worst < 0.9 * remesh_quality_;
    if (forced) {
      remesh(info, "forced (fluid.remesh.at_steps)");
    } else if (poor) {
      try {
        remesh(info, fmt::format("quality {:.3g}, curved {:.3g}", q.min_scaled_jacobian, q.min_curved_jacobian));
      } catch (const std::exception& e) {  // the old mesh is still valid: go on with it
        fsi::logger("fluid")->warn("fluid: remeshing after step {} failed ({}); continuing on the current mesh",
                                   info.step, e.what());
        remesh_quality_ = worst;
      }
    }
  }

  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_log_).count() > 5.0 || info.time >= setup_.end_time - 1e-12) {
    last_log_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double done = setup_.end_time > 0 ? info.time / setup_.end_time : 1.0;
    const double eta = done > 0 ? elapsed * (1 - done) / done : 0.0;
    std::string extra;
    for (const auto& [k, v] : probes)
      if (k != "nonlinear_change" && k != "nonlinear_iterations" && k != "factorisations" && k.rfind("mesh_", 0) != 0)
        extra += fmt::format(" {}={:.6g}", k, v);
    // Debug only: the runner's progress line (step, time, iterations, ETA) is the one at info.
    fsi::logger("fluid")->debug("step {} t={:.4f}/{:.4g} ({:.0f}%) elapsed {:.1f}s ETA {:.1f}s |{}", info.step,
                                info.time, setup_.end_time, 100 * done, elapsed, eta, extra);
  }
  return probes;
}

void NavierStokesFluid::save_state(StateArchive& state) {
  if (solver3_) {
    solver3_->save_state(state, "flow.");
    if (motion3_) motion3_->save_state(state, "mesh.");
    state.put("fluid.last_interface_displacement", last_interface_displacement_);
    state.put("fluid.factorisations", static_cast<std::int64_t>(factorisations_));
    state.put("fluid.solves", static_cast<std::int64_t>(solves_));
    state.put("fluid.linear_iterations", static_cast<std::int64_t>(linear_iterations_));
    return;
  }
  if (!solver_) throw std::logic_error("NavierStokesFluid::save_state before configure()");
  solver_->save_state(state, "flow.");
  if (motion_) motion_->save_state(state, "mesh.");
  state.put("fluid.last_interface_displacement", last_interface_displacement_);
  save_remeshed(state);  // the current mesh (remeshing, --initial-state)
  state.put("fluid.factorisations", static_cast<std::int64_t>(factorisations_));
  state.put("fluid.solves", static_cast<std::int64_t>(solves_));
}

namespace {
// A checkpoint's interface displacement of the last step (both dimensions): the state and this
// configuration agree on a moving mesh and on the number of values (`required`: 2D states have
// always held it; 3D ones written before the 3D interface did not).
Eigen::VectorXd checked_last_displacement(const StateArchive& state, bool moving, std::size_t values, bool required) {
  if (!moving && state.has("mesh.base_displacement"))
    throw StateError(
        "entry 'mesh.base_displacement': the state has a moving mesh, this configuration has no interface");
  const Eigen::VectorXd last = required || state.has("fluid.last_interface_displacement")
                                   ? state.vector("fluid.last_interface_displacement")
                                   : Eigen::VectorXd();
  if (last.size() != 0 && last.size() != static_cast<Eigen::Index>(values))
    throw StateError(
        fmt::format("entry 'fluid.last_interface_displacement' has {} values, this configuration "
                    "needs {} (a different mesh or scene?)",
                    last.size(), values));
  return last;
}
}  // namespace

void NavierStokesFluid::load_state(const StateArchive& state) {
  close_window();
  if (solver3_) {
    const Eigen::VectorXd last =
        checked_last_displacement(state, motion3_ != nullptr, 3 * solver3_->interface_nodes().size(), false);
    solver3_->load_state(state, "flow.");
    if (motion3_) motion3_->load_state(state, "mesh.");
    last_interface_displacement_ = accepted_interface_displacement_ = last;
    // The cumulative counters of probes.csv (a resumed run's table equals a straight run's).
    if (state.has("fluid.factorisations")) {
      factorisations_ = static_cast<int>(state.integer("fluid.factorisations"));
      solves_ = static_cast<int>(state.integer("fluid.solves"));
      linear_iterations_ = static_cast<int>(state.integer("fluid.linear_iterations"));
    }
    return;
  }
  if (!solver_) throw std::logic_error("NavierStokesFluid::load_state before configure()");
  if (const auto saved = state.text("flow.element"); saved != element_)
    throw StateError(
        fmt::format("entry 'flow.element' is '{}', this configuration uses fluid.element {}", saved, element_));
  load_remeshed(state);  // the state's mesh (the scene's, or a remeshed one)
  const Eigen::VectorXd last =
      checked_last_displacement(state, motion_ != nullptr, 2 * solver_->interface_nodes().size(), true);
  const auto factorisations = state.integer("fluid.factorisations"), solves = state.integer("fluid.solves");
  solver_->load_state(state, "flow.");
  if (motion_) motion_->load_state(state, "mesh.");
  last_interface_displacement_ = last;
  accepted_interface_displacement_ = last;  // checkpoints are written between steps
  retried_step_ = -1;
  factorisations_ = static_cast<int>(factorisations);
  solves_ = static_cast<int>(solves);
}

std::vector<std::string> NavierStokesFluid::write_output(const StepInfo& info) {
  if (vtk_every_ == 0 || setup_.output_dir.empty() || (vtk_every_ > 0 && info.step % vtk_every_ != 0)) return {};
  const VtkGrid grid = solver3_ ? flow_vtk_grid(*solver3_) : flow_vtk_grid(*solver_);
  return {vtk_.write(info.time, info.step, grid).string()};
}

}  // namespace fsi::fluid
