// The gamma_N1 terms of Algorithms 1 and 2 cancel exactly at convergence on non-matching,
// deforming interfaces when both sides use the fluid's own interface mass (robin_mass:
// consistent): a finite-element solid coupled in-process to a small Nitsche-coupled "fluid"
// whose interface nodes do not match the solid's and whose interface mass follows the
// deformation. Converged Algorithms 1 and 2 then give the same solid motion, and the
// uncancelled interface work is zero; with the solid's own reference mass it is not.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <fstream>
#include <sstream>

#include "fsi/coupling/coupler.hpp"
#include "fsi/coupling/interface_map.hpp"
#include "fsi/solid/fem_solid.hpp"

namespace {

namespace fs = std::filesystem;

// A lumped "fluid" on a polyline of n_f nodes over the solid's top edge [x0, x1] at height y:
// per node an inertia m_f, a pressure p_0 on the interface, and Nitsche's penalty to the solid
// velocity, m (v_f - v_f,n)/dt + M_f p_0 e_y + gamma M_f (v_f - v_s) = 0, with M_f the P1
// interface mass in the current (deformed) configuration. Its reaction R = m (v_f - v_fn)/dt
// + M_f p_0 e_y is what a solid should feel; it reports f_sigma = R + gamma M_f (v_f - v_s)
// and f_v = M_f v_f as the real fluid server does.
class PenaltyFluid : public fsi::FluidModel {
 public:
  PenaltyFluid(int n, double x0, double x1, double y) {
    x_.resize(n, 2);
    for (int i = 0; i < n; ++i) x_.row(i) << x0 + (x1 - x0) * (i + 0.37 * (i > 0 && i < n - 1)) / (n - 1), y;
  }
  std::string name() const override { return "penalty fluid"; }
  void configure(const fsi::ConfigSection&, const fsi::FluidSetup& s) override {
    gamma_ = s.nitsche_penalty;
    v_n_ = v_ = Eigen::VectorXd::Zero(2 * x_.rows());
  }
  fsi::InterfaceMeshData interface() const override {
    fsi::InterfaceMeshData d;
    d.coordinates = x_;
    for (Eigen::Index i = 0; i < x_.rows(); ++i) d.node_ids.push_back(i);
    for (int i = 0; i + 1 < x_.rows(); ++i) d.segments.push_back({i, i + 1});
    return d;
  }
  fsi::NodalMatrix mass(const Eigen::VectorXd& d) const {
    const Eigen::Index n = x_.rows();
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index i = 0; i + 1 < n; ++i) {
      const Eigen::Vector2d a = x_.row(i).transpose() + d.segment<2>(2 * i);
      const Eigen::Vector2d b = x_.row(i + 1).transpose() + d.segment<2>(2 * i + 2);
      const double L = (b - a).norm();
      t.emplace_back(i, i, L / 3), t.emplace_back(i + 1, i + 1, L / 3);
      t.emplace_back(i, i + 1, L / 6), t.emplace_back(i + 1, i, L / 6);
    }
    fsi::NodalMatrix m(n, n);
    m.setFromTriplets(t.begin(), t.end());
    return m;
  }
  fsi::FluidLoads loads(const Eigen::VectorXd& d, const Eigen::VectorXd& v_s, double dt) {
    const fsi::NodalMatrix m = mass(d);
    const Eigen::Index n = x_.rows();
    Eigen::VectorXd pressure = Eigen::VectorXd::Zero(2 * n);
    for (Eigen::Index i = 0; i < n; ++i) pressure(2 * i + 1) = p0_;
    const Eigen::VectorXd mp = fsi::apply_nodal(m, pressure);
    if (dt > 0) {  // solve (inertia/dt + gamma M_f) v_f = inertia/dt v_fn - M_f p0 + gamma M_f v_s
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
      const Eigen::MatrixXd md(m);
      for (Eigen::Index i = 0; i < n; ++i)
        for (Eigen::Index j = 0; j < n; ++j)
          for (int c = 0; c < 2; ++c) A(2 * i + c, 2 * j + c) = gamma_ * md(i, j) + (i == j) * inertia_ / dt;
      v_ = A.lu().solve(inertia_ / dt * v_n_ - mp + gamma_ * fsi::apply_nodal(m, v_s));
    }
    const Eigen::VectorXd reaction =
        (dt > 0 ? Eigen::VectorXd(inertia_ / dt * (v_ - v_n_)) : Eigen::VectorXd::Zero(2 * n)) + mp;
    fsi::FluidLoads out;
    out.velocity_integral = fsi::apply_nodal(m, v_);
    out.traction_force = reaction + gamma_ * (out.velocity_integral - fsi::apply_nodal(m, v_s));
    out.interface_mass = m;
    out.nonlinear_iterations = 1;
    return out;
  }
  fsi::FluidLoads initial_loads(const Eigen::VectorXd& d, const Eigen::VectorXd& v) override { return loads(d, v, 0); }
  fsi::FluidLoads solve_step(const fsi::StepInfo& info, const Eigen::VectorXd& d, const Eigen::VectorXd& v) override {
    return loads(d, v, info.dt);
  }
  std::map<std::string, double> accept_step(const fsi::StepInfo&) override {
    v_n_ = v_;
    return {};
  }
  bool supports_output() const override { return false; }
  bool supports_checkpoint() const override { return true; }
  void save_state(fsi::StateArchive& state) override { state.put("penalty_fluid.v_n", v_n_); }
  void load_state(const fsi::StateArchive& state) override {
    v_n_ = v_ = state.vector("penalty_fluid.v_n", v_n_.size());
  }

 private:
  Eigen::MatrixX2d x_;
  double gamma_ = 0, inertia_ = 2.0, p0_ = -400.0;
  Eigen::VectorXd v_n_, v_;
};

std::string scene_text(int algorithm, double gamma, const std::string& extra) {
  std::ostringstream s;
  s << "scene: consistent\n"
    << "time: {dt: 0.01, end: 0.2, checkpoint_every: 10}\n"
    << "coupling:\n  algorithm: " << algorithm << "\n  gamma_n1: " << gamma << "\n  relaxation: 0.5\n"
    << "  acceleration: iqn-ils\n  iqn: {reuse_steps: 0}\n"
    << "  iterations: {max: 60, tolerance: 1.0e-13, stop_if_not_converged: false}\n"
    << extra << "solid:\n  model: fem\n"
    << "  mesh: {type: rectangle, origin: [0.0, 0.0], size: [1.0, 0.1], elements: [12, 2]}\n"
    << "  material: {law: saint_venant_kirchhoff, youngs_modulus: 1.0e5, poisson_ratio: 0.3}\n"
    << "  density: 10.0\n  analysis: dynamic\n  time_scheme: bdf1\n  clamp: left\n  interface: [top]\n"
    << "  probes: [{name: A, point: [1.0, 0.1]}]\n"
    << "fluid: {model: penalty}\n";
  return s.str();
}

struct Result {
  fs::path dir;
  std::vector<double> tip_y, uncancelled;
  fsi::coupling::RunOutcome outcome;
};

// Runs the scene in DIR/out; with `fork_from` (another run's folder) first copies its
// checkpoint of step 10 there and continues from it, as fsi run --from does.
Result run(int algorithm, double gamma, const std::string& extra = "", const fs::path& fork_from = {},
           bool keep = false) {
  const auto dir = fs::temp_directory_path() /
                   ("fsi_consistent_" + std::to_string(::getpid()) + "_" + std::to_string(algorithm) + "_" +
                    std::to_string(int(gamma)) + std::to_string(extra.size()) + (fork_from.empty() ? "" : "_fork"));
  fs::remove_all(dir);
  fs::create_directories(dir / "out");
  if (!fork_from.empty()) {
    fs::create_directories(dir / "out" / "checkpoints");
    fs::copy(fork_from / "out" / "checkpoints" / "step_00000010", dir / "out" / "checkpoints" / "step_00000010",
             fs::copy_options::recursive);
    std::ofstream(dir / "out" / "forked_from.json") << R"({"step": 10, "iterations": 0})";
  }
  { std::ofstream(dir / "scene.yaml") << scene_text(algorithm, gamma, extra); }
  const auto scene = fsi::Scene::load(dir / "scene.yaml", {});
  fsi::solid::FemSolid solid;
  PenaltyFluid fluid(9, 0.0, 1.0, 0.1);  // 9 fluid nodes against 13 solid nodes, not at the same places
  fsi::RunReport report(dir / "out", scene, "test");
  fsi::coupling::Coupler coupler(solid, fluid, scene, dir / "out");
  coupler.set_resume(!fork_from.empty());
  Result r;
  r.outcome = coupler.run(report);
  std::ifstream in(dir / "out" / "probes.csv");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> cols;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cols.push_back(c);
  }
  const auto col = [&](const std::string& name) { return std::find(cols.begin(), cols.end(), name) - cols.begin(); };
  const auto iy = col("solid.A_y"), iu = col("coupling.work_uncancelled");
  EXPECT_LT(iy, static_cast<long>(cols.size()));
  EXPECT_LT(iu, static_cast<long>(cols.size()));
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::vector<double> row;
    for (std::string c; std::getline(ss, c, ',');) row.push_back(std::stod(c));
    r.tip_y.push_back(row[static_cast<std::size_t>(iy)]);
    r.uncancelled.push_back(row[static_cast<std::size_t>(iu)]);
  }
  if (!keep) fs::remove_all(dir);
  r.dir = dir;
  return r;
}

double max_relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0, scale = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    diff = std::max(diff, std::abs(a[i] - b[i])), scale = std::max(scale, std::abs(a[i]));
  return diff / scale;
}

TEST(InterfaceMap, MassToSolidConservesTheQuadraticForm) {
  fsi::InterfaceMeshData solid, fluid;
  solid.coordinates.resize(5, 2);
  for (int i = 0; i < 5; ++i) solid.coordinates.row(i) << 0.25 * i, 0.0;
  for (int i = 0; i < 4; ++i) solid.segments.push_back({i, i + 1});
  PenaltyFluid f(4, 0.0, 1.0, 0.0);
  fluid = f.interface();
  const fsi::coupling::InterfaceMap map(solid, fluid);
  const fsi::NodalMatrix mf = f.mass(Eigen::VectorXd::Zero(8));
  const fsi::NodalMatrix mg = map.mass_to_solid(mf);
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(10, -1.0, 2.0).array().sin();
  const Eigen::VectorXd vf = map.to_fluid(v);
  EXPECT_NEAR(v.dot(fsi::apply_nodal(mg, v)), vf.dot(fsi::apply_nodal(mf, vf)), 1e-14);
  // A linear field's integral is exact on both sides: the total measure is the length.
  EXPECT_NEAR(Eigen::MatrixXd(mg).sum(), 1.0, 1e-14);
  // On matching meshes it is the solid's own polyline mass.
  const fsi::coupling::InterfaceMap same(solid, solid);
  const fsi::NodalMatrix own = fsi::coupling::nodal_interface_mass(solid, Eigen::VectorXd());
  EXPECT_LT((Eigen::MatrixXd(same.mass_to_solid(own)) - Eigen::MatrixXd(own)).norm(), 1e-15);
}

TEST(ConsistentCoupling, ConvergedAlgorithms1And2AgreeOnNonMatchingDeformingInterfaces) {
  const Result a1 = run(1, 1000), a2 = run(2, 1000);
  ASSERT_EQ(a1.outcome.status, "completed") << a1.outcome.reason;
  ASSERT_EQ(a2.outcome.status, "completed") << a2.outcome.reason;
  ASSERT_EQ(a1.tip_y.size(), 20u);
  ASSERT_EQ(a2.tip_y.size(), 20u);
  EXPECT_GT(std::abs(a1.tip_y.back()), 1e-4);  // the solid moves
  EXPECT_LT(max_relative_difference(a1.tip_y, a2.tip_y), 1e-8);
  for (double w : a1.uncancelled) EXPECT_EQ(w, 0.0);
  for (double w : a2.uncancelled) EXPECT_EQ(w, 0.0);
}

// Forked at step 10 from converged Algorithm 2 into Algorithm 1 (the force predictor converted
// from Algorithm 2's F = load + gamma M_G v to Algorithm 1's): the same steps 11-20.
TEST(ConsistentCoupling, ForkedFromAlgorithm2IntoAlgorithm1GivesTheSameSteps) {
  const Result a2 = run(2, 1000, "", {}, true);
  ASSERT_EQ(a2.outcome.status, "completed") << a2.outcome.reason;
  const Result a1 = run(1, 1000, "", a2.dir);
  fs::remove_all(a2.dir);
  ASSERT_EQ(a1.outcome.status, "completed") << a1.outcome.reason;
  ASSERT_EQ(a1.tip_y.size(), 10u);
  const std::vector<double> tail(a2.tip_y.begin() + 10, a2.tip_y.end());
  EXPECT_LT(max_relative_difference(tail, a1.tip_y), 1e-8);
}

// With the fluid's penalty gamma_f set apart (coupling.fluid_penalty), the converged coupled
// solution is the fluid's Nitsche solution with gamma_f whatever Algorithm 2's Robin parameter
// gamma_N1: 100 and 3000 give Algorithm 1's history at gamma_f; with one parameter they differ.
TEST(ConsistentCoupling, ConvergedAlgorithm2DoesNotDependOnGammaN1WhenTheFluidPenaltyIsSetApart) {
  const std::string apart = "  fluid_penalty: 1000\n";
  const Result a1 = run(1, 1000), low = run(2, 100, apart), high = run(2, 3000, apart);
  const Result low_one = run(2, 100), high_one = run(2, 3000);
  for (const Result* r : {&a1, &low, &high, &low_one, &high_one}) {
    ASSERT_EQ(r->outcome.status, "completed") << r->outcome.reason;
    ASSERT_EQ(r->tip_y.size(), 20u);
  }
  EXPECT_LT(max_relative_difference(a1.tip_y, low.tip_y), 1e-8);
  EXPECT_LT(max_relative_difference(a1.tip_y, high.tip_y), 1e-8);
  for (double w : low.uncancelled) EXPECT_EQ(w, 0.0);
  for (double w : high.uncancelled) EXPECT_EQ(w, 0.0);
  // One parameter (the paper's): gamma_N1 is the fluid's penalty too, and the answer moves.
  EXPECT_GT(max_relative_difference(low_one.tip_y, high_one.tip_y), 1e-4);
}

TEST(ConsistentCoupling, TheSolidsOwnMassLeavesAnUncancelledTermThatChangesTheAnswer) {
  const Result consistent = run(2, 1000), own = run(2, 1000, "  robin_mass: solid\n");
  ASSERT_EQ(own.outcome.status, "completed") << own.outcome.reason;
  ASSERT_EQ(own.tip_y.size(), 20u);
  // The fluid's 9-node trace cannot hold the solid's 13-node one, and the solid's mass is in
  // the reference configuration: gamma (H^T M_f H - M_G) v_s does work, and the motion differs.
  EXPECT_GT(std::abs(own.uncancelled.back()), 1e-8);
  EXPECT_GT(max_relative_difference(consistent.tip_y, own.tip_y), 1e-4);
}

}  // namespace
