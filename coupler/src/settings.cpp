#include "fsi/coupling/settings.hpp"

#include "fsi/common/scene_reader.hpp"
#include "fsi/coupling/acceleration.hpp"
#include "fsi/coupling/predictor.hpp"

namespace fsi::coupling {

std::string to_string(Algorithm a) {
  return a == Algorithm::ExplicitSolidVelocity ? "1 (explicit solid velocity)"
                                               : "2 (implicit solid velocity, M_fs damping)";
}

std::string to_string(RobinMass m) { return m == RobinMass::Consistent ? "consistent" : "solid"; }

std::string ConvergenceMeasure::name() const {
  const char* q = quantity == MeasureQuantity::Force          ? "force"
                  : quantity == MeasureQuantity::Traction     ? "traction"
                  : quantity == MeasureQuantity::Displacement ? "displacement"
                                                              : "velocity";
  const char* t = type == MeasureType::Absolute   ? "absolute"
                  : type == MeasureType::Relative ? "relative"
                                                  : "residual_relative";
  return std::string(q) + "_" + t;
}

namespace {

void read_relaxation(const schema::Reader& s, CouplingSettings& c) {
  c.beta = s.get<double>("relaxation");
  // The stability limit of the relaxed Dirichlet-Neumann iteration on the added-mass model
  // (README): Algorithm 1: 2 m_eff / (m_eff + m_a) < 2; Algorithm 2: 2 (m_eff + gamma mu dt) /
  // (m_eff + m_a), which grows with gamma (and can exceed 2).
  if (c.algorithm == Algorithm::ExplicitSolidVelocity && !(c.beta < 2.0))
    s.fail("relaxation",
           "(beta) must be in (0, 2) with Algorithm 1 (its stability limit 2 m_eff / (m_eff + m_a) "
           "is below 2)");
}

// coupling.iqn.imvj: IQN-IMVJ's restart.
void read_imvj(const schema::Reader& imvj, CouplingSettings& c) {
  const auto restart = imvj.get<std::string>("restart");
  c.imvj_restart = restart == "rs-0"     ? ImvjRestart::Zero
                   : restart == "rs-ls"  ? ImvjRestart::LeastSquares
                   : restart == "rs-svd" ? ImvjRestart::Svd
                                         : ImvjRestart::None;
  c.imvj_chunk_size = imvj.get<int>("chunk_size");
  c.imvj_restart_reuse_steps = imvj.get<int>("restart_reuse_steps");
  c.imvj_truncation = imvj.get<double>("truncation");
}

// coupling.iqn: the quasi-Newton options.
void read_quasi_newton(const schema::Reader& iqn, CouplingSettings& c) {
  c.reuse_steps = iqn.get_or<int>("reuse_steps", c.reuse_steps);
  c.iqn_filter = iqn.get<double>("filter");
  const auto type = iqn.get<std::string>("filter_type");
  c.iqn_filter_type = type == "qr1" ? QrFilter::Qr1 : type == "qr3" ? QrFilter::Qr3 : QrFilter::Qr2;
  c.iqn_preconditioner =
      iqn.get<std::string>("preconditioner") == "residual-sum" ? Preconditioner::ResidualSum : Preconditioner::None;
  if (iqn.has("imvj") && c.acceleration != "iqn-imvj")
    iqn.fail("imvj", "is only read with 'acceleration: iqn-imvj' (it is '" + c.acceleration + "')");
  read_imvj(iqn.child_or_defaults("imvj"), c);
}

// coupling.predictor, coupling.acceleration and its options (coupling.iqn).
void read_schemes(const schema::Reader& s, CouplingSettings& c) {
  c.predictor = s.get<std::string>("predictor");
  c.acceleration = s.get<std::string>("acceleration");
  c.reuse_steps = accelerator_scheme(c.acceleration).default_reuse_steps;
  if (s.has("iqn") && !accelerator_scheme(c.acceleration).quasi_newton)
    s.fail("iqn",
           "is only read with a quasi-Newton acceleration, 'iqn-ils' or 'iqn-imvj' (it is '" + c.acceleration + "')");
  read_quasi_newton(s.child_or_defaults("iqn"), c);
}

ConvergenceMeasure read_measure(const schema::Reader& m) {
  ConvergenceMeasure cm;
  const auto q = m.get<std::string>("quantity");
  cm.quantity = q == "traction"       ? MeasureQuantity::Traction
                : q == "displacement" ? MeasureQuantity::Displacement
                : q == "velocity"     ? MeasureQuantity::Velocity
                                      : MeasureQuantity::Force;
  const auto t = m.get<std::string>("type");
  cm.type = t == "absolute"            ? MeasureType::Absolute
            : t == "residual-relative" ? MeasureType::ResidualRelative
                                       : MeasureType::Relative;
  cm.limit = m.get<double>("limit");
  cm.strict = m.get<bool>("strict");
  return cm;
}

// coupling.iterations: k_max, the tolerance or the measures, and how they combine.
void read_iterations(const schema::Reader& it, CouplingSettings& c) {
  c.max_iterations = it.get<int>("max");
  c.tolerance = it.get<double>("tolerance");
  c.stop_if_not_converged = it.get<bool>("stop_if_not_converged");
  c.divergence_factor = it.get<double>("divergence_factor");
  if (c.tolerance > 0) c.measures.push_back({MeasureQuantity::Force, MeasureType::Relative, c.tolerance, false});
  for (const auto& m : it.list("measures")) {
    if (it.has("tolerance") && c.tolerance > 0)
      it.fail("measures", "give either 'tolerance' (the relative force change) or 'measures', not both");
    const ConvergenceMeasure cm = read_measure(m);
    for (const auto& other : c.measures)
      if (other.name() == cm.name()) m.fail("quantity", "measure '" + cm.name() + "' is given twice");
    c.measures.push_back(cm);
  }
  c.combine_all = it.get<std::string>("combine") == "all";
}

// coupling.mapping and Wendland's coupling.support_radius.
void read_mapping(const schema::Reader& s, CouplingSettings& c) {
  const auto mapping = s.get<std::string>("mapping");
  c.mapping.kind = mapping == "rbf-tps"           ? MappingKind::RbfThinPlateSpline
                   : mapping == "rbf-wendland-c2" ? MappingKind::RbfWendlandC2
                                                  : MappingKind::NearestSegment;
  if (s.has("support_radius")) {
    if (c.mapping.kind != MappingKind::RbfWendlandC2)
      s.fail("support_radius", "is only read with 'mapping: rbf-wendland-c2' (it is '" + mapping + "')");
    c.mapping.support_radius = s.get_or<double>("support_radius", c.mapping.support_radius);
  }
}

}  // namespace

CouplingSettings read_coupling(const ConfigSection& section) {
  const schema::Reader s(section, coupling_section());
  CouplingSettings c;
  c.algorithm = static_cast<Algorithm>(s.get<int>("algorithm"));
  const auto scheme = s.get<std::string>("scheme");
  c.scheme = scheme == "parallel"        ? CouplingScheme::Parallel
             : scheme == "robin-neumann" ? CouplingScheme::RobinNeumann
                                         : CouplingScheme::Serial;
  if (s.has("robin_neumann_order") && c.scheme != CouplingScheme::RobinNeumann)
    s.fail("robin_neumann_order", "is only read with 'scheme: robin-neumann' (it is '" + scheme + "')");
  c.robin_neumann_order = s.get<int>("robin_neumann_order");
  c.gamma_n1 = s.get<double>("gamma_n1");
  const auto robin_auto = s.get<std::string>("robin_auto");
  c.robin_auto = robin_auto == "solid"   ? RobinAuto::Solid
                 : robin_auto == "fluid" ? RobinAuto::Fluid
                 : robin_auto == "both"  ? RobinAuto::Both
                                         : RobinAuto::None;
  if ((c.robin_auto == RobinAuto::Solid || c.robin_auto == RobinAuto::Both) &&
      c.algorithm != Algorithm::ImplicitSolidVelocity)
    s.fail("robin_auto", "on the solid side needs algorithm 2 (Algorithm 1 has no Robin term on the solid)");
  c.gamma_f = s.get_or<double>("fluid_penalty", c.gamma_n1);
  if (c.gamma_f == 0 && c.gamma_n1 > 0)
    s.fail("fluid_penalty",
           "must be > 0 when gamma_n1 > 0 (the fluid imposes the solid's velocity by Nitsche's "
           "method with this penalty)");
  c.gamma_n2 = s.get<double>("gamma_n2");
  read_relaxation(s, c);
  read_schemes(s, c);
  read_iterations(s.child("iterations"), c);
  if (c.scheme == CouplingScheme::RobinNeumann) {
    if (c.max_iterations != 1)
      s.fail("scheme", "robin-neumann is explicit, one pass per step: give iterations.max 1 (it is " +
                           std::to_string(c.max_iterations) + ")");
    if (!c.measures.empty())
      s.fail("scheme",
             "robin-neumann is explicit: it has no coupling iterations to converge; give iterations.tolerance 0 and no "
             "iterations.measures");
    if (c.algorithm == Algorithm::ImplicitSolidVelocity && c.gamma_n1 > 0)
      s.fail("scheme",
             "robin-neumann gives the solid the fluid's traction only: Algorithm 2's damping (gamma_n1 > 0) does not "
             "apply; use algorithm 1");
  }
  c.robin_mass = s.get<std::string>("robin_mass") == "solid" ? RobinMass::Solid : RobinMass::Consistent;
  read_mapping(s, c);
  c.force_limit = s.get<double>("force_limit");
  c.growth_factor = s.child_or_defaults("growth").get<double>("factor");
  c.growth_window = s.child_or_defaults("growth").get<int>("window");
  c.gap_warn = s.child_or_defaults("interface_gap").get<double>("warn");
  c.gap_refuse = s.child_or_defaults("interface_gap").get<double>("refuse");
  return c;
}

}  // namespace fsi::coupling
