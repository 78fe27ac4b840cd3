// Configuring a run: the scene's time and coupling sections, both solvers, the interface map,
// and the set-up's report (summary.json's "interface" and "coupling", log lines, warnings).
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <future>
#include <limits>
#include <tuple>

#include "fsi/common/interface_geometry.hpp"
#include "fsi/common/write_check.hpp"
#include "fsi/coupling/coupler.hpp"
#include "fsi/coupling/predictor.hpp"
#include "run_parts.hpp"

namespace fsi::coupling {
using namespace run_detail;

TimeSettings Coupler::configure(InterfaceMeshData& fluid_interface) {
  auto log = logger("coupler");
  scene_.name();
  schema::require_valid(scene_, {"time", "coupling"});  // every key, before anything is configured
  const TimeSettings time = read_time(scene_);
  settings_ = read_coupling(scene_.section("coupling"));
  scene_.check_all_used("coupling");
  scene_.check_all_used("time");
  // The top-level keys are the schema's (scene, description, units, time, the declared sections),
  // and the peers' sections, which the peers check.
  std::vector<std::string> known;
  for (const auto& k : schema::scene_keys()) known.push_back(k.name);
  for (const char* peer : {"solid", "fluid"})
    if (std::find(known.begin(), known.end(), peer) == known.end()) known.emplace_back(peer);
  for (const auto& key : scene_.root().keys())
    if (std::find(known.begin(), known.end(), key) == known.end())
      throw ConfigError(fmt::format("{}: unknown top-level section '{}' (known: {})", scene_.root().where(key), key,
                                    fmt::join(known, ", ")));
  // The warning is for loosely coupled runs (a fixed number of iterations): converged
  // iterations take the unconverged modes down whatever the predictor.
  if (settings_.predictor != "previous" && settings_.tolerance <= 0)
    log->warn(
        "predictor '{}' ({}) can excite interface modes the iterations leave unconverged (docs/fsi.md); "
        "'previous' is the paper's and the robust choice",
        settings_.predictor, predictor_scheme(settings_.predictor).phrase);
  if (settings_.robin_auto != RobinAuto::None) automatic_robin(time);
  const double gamma = settings_.gamma_n1;
  const bool implicit = settings_.algorithm == Algorithm::ImplicitSolidVelocity;
  if (implicit && gamma > 0 && !solid_.supports_interface_damping())
    throw Stop{"failed",
               fmt::format("Algorithm 2 needs interface damping, which solid '{}' does not support", solid_.name())};
  const auto vtk_dir = out_dir_ / "vtk";
  {
    Timer t(times_.solid);
    solid_.configure(scene_.section("solid"),
                     SolidSetup{time.dt, time.end, implicit ? gamma : 0.0,
                                time.output_every > 0 ? vtk_dir : std::filesystem::path(), time.vtk_format});
  }
  {
    Timer t(times_.fluid);
    fluid_.configure(scene_.section("fluid"),
                     FluidSetup{time.dt, time.end, settings_.gamma_f, settings_.gamma_n2,
                                time.output_every > 0 ? vtk_dir : std::filesystem::path(), time.vtk_format});
  }
  solid_interface_ = solid_.interface();
  fluid_interface = fluid_.interface();
  // Waveform iterations: each solver's substeps in a window, from its own section.
  solid_substeps_ = substeps_of(scene_.section("solid"));
  fluid_substeps_ = substeps_of(scene_.section("fluid"));
  const auto refuse_substeps = [&](const char* section, int n, bool supported, const std::string& name) {
    if (n > 1 && !supported)
      throw Stop{"failed", fmt::format("{}.substeps: {} needs a {} that takes substeps (waveform iterations), which "
                                       "{} '{}' does not (ConfigureReply.supports_substeps); set {}.substeps: 1",
                                       section, n, section, section, name, section)};
    if (n > 1 && settings_.scheme == CouplingScheme::RobinNeumann)
      throw Stop{"failed", fmt::format("{}.substeps: {} with coupling.scheme robin-neumann: the explicit scheme "
                                       "takes one step per window (waveform iterations need scheme serial or "
                                       "parallel)",
                                       section, n)};
  };
  refuse_substeps("solid", solid_substeps_, solid_.supports_substeps(), solid_.name());
  refuse_substeps("fluid", fluid_substeps_, fluid_.supports_substeps(), fluid_.name());
  {
    Timer t(times_.coupler);
    try {
      map_ = InterfaceMap(solid_interface_, fluid_interface, settings_.mapping);
    } catch (const std::invalid_argument& e) {
      throw Stop{"failed", fmt::format("solid '{}' and fluid '{}': {}", solid_.name(), fluid_.name(), e.what())};
    }
  }
  return time;
}

// coupling.robin_auto: the solid configured once without damping to report its mass per
// interface measure; gamma_auto = (m_s / |Gamma|) / dt replaces gamma_N1, gamma_f or both.
void Coupler::automatic_robin(const TimeSettings& time) {
  {
    Timer t(times_.solid);
    solid_.configure(scene_.section("solid"), SolidSetup{time.dt, time.end, 0.0, {}});
  }
  const double mass_per_area = solid_.interface().mass_per_area;
  if (!(mass_per_area > 0))
    throw Stop{"failed", fmt::format("coupling.robin_auto needs the solid's mass per interface measure, which "
                                     "solid '{}' does not report (InterfaceMesh.mass_per_area)",
                                     solid_.name())};
  robin_auto_value_ = mass_per_area / time.dt;
  if (settings_.robin_auto != RobinAuto::Fluid) settings_.gamma_n1 = robin_auto_value_;
  if (settings_.robin_auto != RobinAuto::Solid) settings_.gamma_f = robin_auto_value_;
  if (settings_.gamma_n1 > 0 && settings_.gamma_f == 0)
    throw Stop{"failed",
               "coupling.robin_auto: solid sets gamma_N1 > 0 with a fluid penalty of 0: give "
               "coupling.fluid_penalty, or robin_auto: both"};
  logger("coupler")->info(
      "automatic Robin parameter: m_s / |Gamma| = {:.6g}, over dt = {:.6g}: gamma_N1 = {:.6g}, "
      "gamma_f = {:.6g}",
      mass_per_area, time.dt, settings_.gamma_n1, settings_.gamma_f);
}

// The gap between the two interfaces against the solid's median element size: meshes in
// different frames, units or places map every fluid node onto the solid's nearest edge and run
// on without an error, so a large gap is refused (coupling.interface_gap).
void Coupler::check_gap(nlohmann::json& data, const InterfaceMeshData& fluid_interface) const {
  const auto& solid = solid_interface_;
  std::vector<double> sizes;
  const Eigen::MatrixXd& x = solid.coordinates;
  for (const auto& s : solid.segments) sizes.push_back((x.row(s[1]) - x.row(s[0])).norm());
  for (const auto& f : solid.faces) sizes.push_back(std::sqrt(face_area(x, f)));
  // A point interface: no element size to measure the gap against; a one-node fluid (a model
  // such as the surrogate, which pushes wherever the solid is) has no place to be off.
  if (sizes.empty() || fluid_interface.nodes() == 1) return;
  std::nth_element(sizes.begin(), sizes.begin() + static_cast<std::ptrdiff_t>(sizes.size() / 2), sizes.end());
  const double h = sizes[sizes.size() / 2];
  const double ratio = h > 0 ? map_.max_gap() / h : 0;
  data["interface"]["element_size"] = h;
  data["interface"]["gap_ratio"] = ratio;
  if (ratio <= settings_.gap_warn) return;
  const std::string what = fmt::format(
      "the fluid's interface lies up to {:.3g} m from the solid's ({:.0f} % of the solid interface's median element "
      "size {:.3g} m): are the two meshes in the same frame and units, and is the solid where the fluid's mesh "
      "expects it (its origin)?",
      map_.max_gap(), 100 * ratio, h);
  if (settings_.gap_refuse > 0 && ratio > settings_.gap_refuse)
    throw Stop{"failed", what + fmt::format(" Refused above {:.0f} % (coupling.interface_gap.refuse)",
                                            100 * settings_.gap_refuse)};
  logger("coupler")->warn("{} (warned above {:.0f} %: coupling.interface_gap.warn)", what, 100 * settings_.gap_warn);
}

void Coupler::describe_setup(nlohmann::json& data, const TimeSettings& time, const InterfaceMeshData& fluid_interface) {
  auto log = logger("coupler");
  const double gamma = settings_.gamma_n1;
  const bool implicit = settings_.algorithm == Algorithm::ImplicitSolidVelocity;
  const Eigen::Index ns = static_cast<Eigen::Index>(solid_interface_.nodes());
  if (time.output_every > 0)
    for (const auto& [side, ok, who] : {std::tuple{"solid", solid_.supports_output(), solid_.name()},
                                        std::tuple{"fluid", fluid_.supports_output(), fluid_.name()}})
      if (!ok) log->warn("time.output_every: the {} '{}' cannot write output (supports_output is false)", side, who);
  // Point interfaces: both sides' measures (int N^T N) should agree, or the Robin terms
  // weigh the two sides differently (in effect a damping of the wrong size or sign).
  if (solid_interface_.points_only() && fluid_interface.points_only() &&
      solid_interface_.lumped_measure.size() == fluid_interface.lumped_measure.size()) {
    const double a = solid_interface_.lumped_measure.sum(), b = fluid_interface.lumped_measure.sum();
    if (std::abs(a - b) > 1e-9 * std::max(std::abs(a), std::abs(b)))
      log->warn("interface measures differ: solid {} vs fluid {} (interface_measure of the two sections)", a, b);
  }
  data["interface"] = {{"solid_nodes", ns},
                       {"fluid_nodes", fluid_interface.nodes()},
                       {"max_gap", map_.max_gap()},
                       {"conforming", map_.conforming()},
                       {"coincident_nodes", map_.coincident_nodes()},
                       {"mapping", to_string(map_.kind())}};
  if (map_.kind() != MappingKind::NearestSegment) {
    data["interface"]["rbf"] = {{"support_radius", map_.support_radius()},
                                {"linear_terms", map_.linear_terms()},
                                {"condition", map_.condition_estimate()}};
    log->info("mapping {}: RBF on the {} solid interface nodes, {} linear terms{}, condition estimate {:.3g}",
              to_string(map_.kind()), ns, map_.linear_terms(),
              map_.support_radius() > 0 ? fmt::format(", support radius {:.4g} m", map_.support_radius()) : "",
              map_.condition_estimate());
  }
  check_gap(data, fluid_interface);
  if (map_.conforming()) {
    data["interface"]["permutation_error"] = map_.permutation_error();
    log->info(
        "conforming interface: the {} fluid nodes are the solid's (max gap {:.3g} m), H is a permutation "
        "(max |H - P| {:.3g})",
        fluid_interface.nodes(), map_.max_gap(), map_.permutation_error());
  } else {
    log->info(
        "non-conforming interface: {} of the {} fluid nodes coincide with one of the {} solid nodes "
        "(within {:.3g} m), max gap to the solid's interface {:.3g} m: H interpolates",
        map_.coincident_nodes(), fluid_interface.nodes(), ns, map_.coincidence_tolerance(), map_.max_gap());
  }
  // Algorithm 2 far above the solid's interface impedance Z_s = m_s / |Gamma| / dt: converged
  // iterations contract by about 1 - beta (Z_s + Z_f) / (Z_s + gamma_N1), so their number
  // grows like gamma_N1 / Z_s.
  impedance_ratio_ = 0;
  if (implicit && gamma > 0 && solid_interface_.mass_per_area > 0) {
    const double z_s = solid_interface_.mass_per_area / time.dt;
    impedance_ratio_ = gamma / z_s;
    data["coupling_estimate"] = {{"solid_impedance", z_s}, {"gamma_over_impedance", impedance_ratio_}};
    if (impedance_ratio_ > 10 && settings_.max_iterations > 1)
      log->warn(
          "Algorithm 2: gamma_N1 = {:.4g} is {:.3g} times the solid's interface impedance m_s / |Gamma| / dt = "
          "{:.4g}: converged coupling iterations contract by about 1 - beta (Z_s + Z_f) / (Z_s + gamma_N1), so expect "
          "their number to grow like that ratio (coupling.robin_auto: solid sets gamma_N1 to the impedance)",
          gamma, impedance_ratio_, z_s);
  }
  consistent_damping_ = implicit && gamma > 0 && settings_.robin_mass == RobinMass::Consistent;
  if (consistent_damping_ && !solid_.supports_interface_mass()) {
    consistent_damping_ = false;
    log->warn(
        "the solid '{}' does not take the interface mass (supports_interface_mass): Algorithm 2's damping "
        "uses its own int N^T N, and the gamma_N1 terms do not cancel exactly at convergence "
        "(coupling.work_uncancelled in probes.csv)",
        solid_.name());
  }
  data["coupling"] = {{"algorithm", static_cast<int>(settings_.algorithm)},
                      {"gamma_n1", gamma},
                      {"fluid_penalty", settings_.gamma_f},
                      {"gamma_n2", settings_.gamma_n2},
                      {"relaxation", settings_.beta},
                      {"max_iterations", settings_.max_iterations},
                      {"tolerance", settings_.tolerance},
                      {"acceleration", settings_.acceleration},
                      {"robin_mass", to_string(settings_.robin_mass)}};
  nlohmann::json measures = nlohmann::json::array();
  for (const auto& m : settings_.measures)
    measures.push_back({{"name", m.name()}, {"limit", m.limit}, {"strict", m.strict}});
  data["coupling"]["measures"] = measures;
  data["coupling"]["combine"] = settings_.combine_all ? "all" : "any";
  data["coupling"]["predictor"] = settings_.predictor;
  if (settings_.robin_auto != RobinAuto::None)
    data["coupling"]["robin_auto"] = {{"value", robin_auto_value_},
                                      {"mass_per_area", solid_interface_.mass_per_area},
                                      {"side", settings_.robin_auto == RobinAuto::Solid   ? "solid"
                                               : settings_.robin_auto == RobinAuto::Fluid ? "fluid"
                                                                                          : "both"}};
  if (accelerator_scheme(settings_.acceleration).quasi_newton) {
    const char* filters[] = {"qr1", "qr2", "qr3"};
    const char* restarts[] = {"none", "rs-0", "rs-ls", "rs-svd"};
    data["coupling"]["iqn"] = {
        {"reuse_steps", settings_.reuse_steps},
        {"filter", settings_.iqn_filter},
        {"filter_type", filters[static_cast<int>(settings_.iqn_filter_type)]},
        {"preconditioner", settings_.iqn_preconditioner == Preconditioner::None ? "none" : "residual-sum"}};
    if (settings_.acceleration == "iqn-imvj")
      data["coupling"]["iqn"]["imvj"] = {{"restart", restarts[static_cast<int>(settings_.imvj_restart)]},
                                         {"chunk_size", settings_.imvj_chunk_size},
                                         {"restart_reuse_steps", settings_.imvj_restart_reuse_steps},
                                         {"truncation", settings_.imvj_truncation}};
  }
  log->info("algorithm {}, gamma_N1 = {}, beta = {}, k_max = {}, tolerance = {}; {} solid / {} fluid interface nodes",
            to_string(settings_.algorithm), gamma, settings_.beta, settings_.max_iterations, settings_.tolerance, ns,
            fluid_interface.nodes());
  if (settings_.gamma_f != gamma)
    log->info("the fluid's Nitsche penalty gamma_f = {} is set apart from gamma_N1{}", settings_.gamma_f,
              implicit ? "" : " (Algorithm 1 uses gamma_f only: gamma_N1 has no effect)");
}

void Coupler::write_output(Run& r, const StepInfo& info, const InterfaceFields& fields) {
  ++r.output_requests;
  if (solid_.supports_output()) {
    Timer t(times_.solid);
    r.files_written["solid"] += solid_.write_output(info).size();
  }
  if (fluid_.supports_output()) {
    Timer t(times_.fluid);
    r.files_written["fluid"] += fluid_.write_output(info).size();
  }
  {
    Timer t(times_.coupler);
    r.interface_output->write(info.time, info.step, fields);
  }
  if (r.output_requests == 3)
    for (const auto& [side, ok, who] : {std::tuple{"solid", solid_.supports_output(), solid_.name()},
                                        std::tuple{"fluid", fluid_.supports_output(), fluid_.name()}})
      if (ok && r.files_written[side] == 0)
        r.log->warn(
            "time.output_every = {}: the {} '{}' wrote no VTK in {} requests (does its section turn "
            "output off? {})",
            r.time.output_every, side, who, r.output_requests,
            std::string(side) == "solid" ? "solid.output_every" : "fluid.output.vtk_every");
}

NodalMatrix Coupler::map_mass(Run& r, const FluidLoads& loads) {
  if (loads.interface_mass.rows() == 0) {
    if (!r.warned_no_fluid_mass && r.gamma_n1 > 0 && settings_.robin_mass == RobinMass::Consistent)
      r.log->warn(
          "the fluid '{}' does not send its interface mass M_f: the gamma_N1 terms use the solid's "
          "polyline int N^T N and cancel at convergence only where it equals H^T M_f H",
          fluid_.name());
    r.warned_no_fluid_mass = true;
    return NodalMatrix();
  }
  try {
    return map_.mass_to_solid(loads.interface_mass);
  } catch (const std::invalid_argument& e) {
    throw Stop{"failed", fmt::format("fluid '{}': {}", fluid_.name(), e.what())};
  }
}

}  // namespace fsi::coupling
