#include "fsi/coupling/settings.hpp"

#include "fsi/coupling/acceleration.hpp"
#include "fsi/coupling/predictor.hpp"

namespace fsi::coupling {

std::string to_string(Algorithm a) {
  return a == Algorithm::ExplicitSolidVelocity ? "1 (explicit solid velocity)" : "2 (implicit solid velocity, M_fs damping)";
}

std::string to_string(RobinMass m) { return m == RobinMass::Consistent ? "consistent" : "solid"; }

std::string ConvergenceMeasure::name() const {
  const char* q = quantity == MeasureQuantity::Force      ? "force"
                  : quantity == MeasureQuantity::Traction ? "traction"
                  : quantity == MeasureQuantity::Displacement ? "displacement"
                                                              : "velocity";
  const char* t = type == MeasureType::Absolute ? "absolute" : type == MeasureType::Relative ? "relative"
                                                                                              : "residual_relative";
  return std::string(q) + "_" + t;
}

namespace {

// "'a' (what a is), 'b' (...) or 'c' (...)" for a choice's error message.
template <typename Schemes>
std::string choices(const Schemes& schemes) {
  std::string out;
  for (std::size_t i = 0; i < schemes.size(); ++i) {
    if (i > 0) out += i + 1 == schemes.size() ? " or " : ", ";
    out += "'" + schemes[i].name + "' (" + schemes[i].phrase + ")";
  }
  return out;
}

template <typename Schemes>
bool known(const Schemes& schemes, const std::string& name) {
  for (const auto& s : schemes)
    if (s.name == name) return true;
  return false;
}

void read_relaxation(const ConfigSection& s, CouplingSettings& c) {
  c.relaxation = s.get<double>("relaxation");
  // The stability limit of the relaxed Dirichlet-Neumann iteration on the added-mass model
  // (README): Algorithm 1: 2 m_eff / (m_eff + m_a) < 2; Algorithm 2: 2 (m_eff + gamma mu dt) /
  // (m_eff + m_a), which grows with gamma (and can exceed 2).
  if (!(c.relaxation > 0)) s.fail("relaxation", "(beta) must be > 0");
  if (c.algorithm == Algorithm::ExplicitSolidVelocity && !(c.relaxation < 2.0))
    s.fail("relaxation", "(beta) must be in (0, 2) with Algorithm 1 (its stability limit 2 m_eff / (m_eff + m_a) "
                         "is below 2)");
}

// coupling.iqn.imvj: IQN-IMVJ's restart.
void read_imvj(const ConfigSection& imvj, CouplingSettings& c) {
  const auto restart = imvj.get<std::string>("restart", "none");
  if (restart == "none") c.imvj_restart = ImvjRestart::None;
  else if (restart == "rs-0") c.imvj_restart = ImvjRestart::Zero;
  else if (restart == "rs-ls") c.imvj_restart = ImvjRestart::LeastSquares;
  else if (restart == "rs-svd") c.imvj_restart = ImvjRestart::Svd;
  else imvj.fail("restart", "must be 'none' (the Jacobian carried over), 'rs-0', 'rs-ls' or 'rs-svd'");
  c.imvj_chunk_size = imvj.get<int>("chunk_size", 8);
  if (c.imvj_chunk_size < 1) imvj.fail("chunk_size", "must be >= 1");
  c.imvj_restart_reuse_steps = imvj.get<int>("restart_reuse_steps", 8);
  if (c.imvj_restart_reuse_steps < 1) imvj.fail("restart_reuse_steps", "must be >= 1");
  c.imvj_truncation = imvj.get<double>("truncation", 1e-4);
  if (!(c.imvj_truncation >= 0 && c.imvj_truncation < 1)) imvj.fail("truncation", "must be in [0, 1)");
}

// coupling.iqn: the quasi-Newton options.
void read_quasi_newton(const ConfigSection& iqn, CouplingSettings& c) {
  c.reuse_steps = iqn.get<int>("reuse_steps", c.reuse_steps);
  if (c.reuse_steps < 0) iqn.fail("reuse_steps", "must be >= 0");
  c.iqn_filter = iqn.get<double>("filter", 1e-3);
  if (!(c.iqn_filter > 0 && c.iqn_filter < 1)) iqn.fail("filter", "must be in (0, 1)");
  const auto type = iqn.get<std::string>("filter_type", "qr2");
  if (type == "qr1") c.iqn_filter_type = QrFilter::Qr1;
  else if (type == "qr2") c.iqn_filter_type = QrFilter::Qr2;
  else if (type == "qr3") c.iqn_filter_type = QrFilter::Qr3;
  else iqn.fail("filter_type", "must be 'qr1', 'qr2' or 'qr3'");
  const auto pre = iqn.get<std::string>("preconditioner", "none");
  if (pre == "none") c.iqn_preconditioner = Preconditioner::None;
  else if (pre == "residual-sum") c.iqn_preconditioner = Preconditioner::ResidualSum;
  else iqn.fail("preconditioner", "must be 'none' or 'residual-sum'");
  if (iqn.has("imvj")) {
    if (c.acceleration != "iqn-imvj")
      iqn.fail("imvj", "is only read with 'acceleration: iqn-imvj' (it is '" + c.acceleration + "')");
    read_imvj(iqn.child("imvj"), c);
  }
}

// coupling.predictor, coupling.acceleration and its options (coupling.iqn).
void read_schemes(const ConfigSection& s, CouplingSettings& c) {
  c.predictor = s.get<std::string>("predictor", "previous");
  if (!known(predictor_schemes(), c.predictor)) s.fail("predictor", "must be " + choices(predictor_schemes()));
  c.acceleration = s.get<std::string>("acceleration", "constant");
  if (!known(accelerator_schemes(), c.acceleration))
    s.fail("acceleration", "must be " + choices(accelerator_schemes()));
  c.reuse_steps = accelerator_scheme(c.acceleration).default_reuse_steps;
  if (s.has("iqn")) {
    const auto iqn = s.child("iqn");
    if (!accelerator_scheme(c.acceleration).quasi_newton)
      s.fail("iqn", "is only read with a quasi-Newton acceleration, 'iqn-ils' or 'iqn-imvj' (it is '" +
                        c.acceleration + "')");
    read_quasi_newton(iqn, c);
  }
}

ConvergenceMeasure read_measure(const ConfigSection& m) {
  ConvergenceMeasure cm;
  const auto q = m.get<std::string>("quantity");
  if (q == "force") cm.quantity = MeasureQuantity::Force;
  else if (q == "traction") cm.quantity = MeasureQuantity::Traction;
  else if (q == "displacement") cm.quantity = MeasureQuantity::Displacement;
  else if (q == "velocity") cm.quantity = MeasureQuantity::Velocity;
  else m.fail("quantity", "must be 'force', 'traction', 'displacement' or 'velocity', got '" + q + "'");
  const auto t = m.get<std::string>("type", "relative");
  if (t == "absolute") cm.type = MeasureType::Absolute;
  else if (t == "relative") cm.type = MeasureType::Relative;
  else if (t == "residual-relative") cm.type = MeasureType::ResidualRelative;
  else m.fail("type", "must be 'absolute', 'relative' or 'residual-relative', got '" + t + "'");
  cm.limit = m.get<double>("limit");
  if (!(cm.limit > 0)) m.fail("limit", "must be > 0");
  cm.strict = m.get<bool>("strict", false);
  return cm;
}

// coupling.iterations: k_max, the tolerance or the measures, and how they combine.
void read_iterations(const ConfigSection& it, CouplingSettings& c) {
  c.max_iterations = it.get<int>("max");
  if (c.max_iterations < 1) it.fail("max", "must be >= 1");
  c.tolerance = it.get<double>("tolerance", 0.0);
  if (c.tolerance < 0) it.fail("tolerance", "must be >= 0 (0 = fixed number of iterations)");
  c.stop_if_not_converged = it.get<bool>("stop_if_not_converged", true);
  c.divergence_factor = it.get<double>("divergence_factor", 1e4);
  if (!(c.divergence_factor > 1)) it.fail("divergence_factor", "must be > 1");
  if (c.tolerance > 0) c.measures.push_back({MeasureQuantity::Force, MeasureType::Relative, c.tolerance, false});
  for (const auto& m : it.list("measures")) {
    if (it.has("tolerance") && c.tolerance > 0)
      it.fail("measures", "give either 'tolerance' (the relative force change) or 'measures', not both");
    const ConvergenceMeasure cm = read_measure(m);
    for (const auto& other : c.measures)
      if (other.name() == cm.name()) m.fail("quantity", "measure '" + cm.name() + "' is given twice");
    c.measures.push_back(cm);
  }
  const auto combine = it.get<std::string>("combine", "all");
  if (combine == "all") c.combine_all = true;
  else if (combine == "any") c.combine_all = false;
  else it.fail("combine", "must be 'all' (every measure holds) or 'any'");
}

}  // namespace

CouplingSettings read_coupling(const ConfigSection& s) {
  CouplingSettings c;
  const int algorithm = s.get<int>("algorithm");
  if (algorithm != 1 && algorithm != 2) s.fail("algorithm", "must be 1 (explicit) or 2 (implicit solid velocity)");
  c.algorithm = static_cast<Algorithm>(algorithm);
  const auto scheme = s.get<std::string>("scheme", "serial");
  if (scheme == "serial") c.scheme = CouplingScheme::Serial;
  else if (scheme == "parallel") c.scheme = CouplingScheme::Parallel;
  else s.fail("scheme", "must be 'serial' (solid, then fluid: the paper) or 'parallel' (both at once)");
  c.nitsche_penalty = s.get<double>("gamma_n1");
  if (c.nitsche_penalty < 0) s.fail("gamma_n1", "must be >= 0");
  const auto robin_auto = s.get<std::string>("robin_auto", "none");
  if (robin_auto == "none") c.robin_auto = RobinAuto::None;
  else if (robin_auto == "solid") c.robin_auto = RobinAuto::Solid;
  else if (robin_auto == "fluid") c.robin_auto = RobinAuto::Fluid;
  else if (robin_auto == "both") c.robin_auto = RobinAuto::Both;
  else s.fail("robin_auto", "must be 'none', 'solid', 'fluid' or 'both'");
  if ((c.robin_auto == RobinAuto::Solid || c.robin_auto == RobinAuto::Both) && algorithm != 2)
    s.fail("robin_auto", "on the solid side needs algorithm 2 (Algorithm 1 has no Robin term on the solid)");
  c.fluid_penalty = s.get<double>("fluid_penalty", c.nitsche_penalty);
  if (c.fluid_penalty < 0) s.fail("fluid_penalty", "must be >= 0");
  if (c.fluid_penalty == 0 && c.nitsche_penalty > 0)
    s.fail("fluid_penalty", "must be > 0 when gamma_n1 > 0 (the fluid imposes the solid's velocity by Nitsche's "
                            "method with this penalty)");
  c.nitsche_symmetry = s.get<double>("gamma_n2", -1.0);
  if (c.nitsche_symmetry != 1.0 && c.nitsche_symmetry != -1.0) s.fail("gamma_n2", "must be +1 or -1");
  read_relaxation(s, c);
  read_schemes(s, c);
  read_iterations(s.child("iterations"), c);
  const auto robin = s.get<std::string>("robin_mass", "consistent");
  if (robin == "consistent") c.robin_mass = RobinMass::Consistent;
  else if (robin == "solid") c.robin_mass = RobinMass::Solid;
  else s.fail("robin_mass", "must be 'consistent' (the fluid's H^T M_f H) or 'solid' (the solid's own int N^T N)");
  c.force_limit = s.get<double>("force_limit", 1e12);
  if (!(c.force_limit > 0)) s.fail("force_limit", "must be positive");
  return c;
}

}  // namespace fsi::coupling
