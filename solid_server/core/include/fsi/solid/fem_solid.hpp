#pragma once
// FemSolid: the finite-strain solid as an fsi::SolidModel, in 2D (plane strain Q4) or 3D
// (Hex8 or Tet10), the dimension and cell kind taken from its mesh.
//
// Call order (the contract of solver_model.hpp):
//   configure(section, setup) -> interface() -> { solve_step(info, F) ... accept_step(info) } -> write_output(info)
// Each solve_step restarts from the last accepted state, so the coupler may call it any
// number of times per step. Standalone use passes a zero interface force (or an empty
// vector when the scene defines no interface); gravity and edge loads come from the section.
//
// Equations (paper, eq. solid-discrete-impl2):  M a + M_fs v + F_int(d) = F_ext + F_interface
//   M_fs = gamma_N1 * int_interface N^T N dgamma  (reference configuration; only when the
//   coupler sets SolidSetup::interface_damping > 0).
// Schemes: `bdf1` (the paper: v = (d - d_n)/dt, a = (v - v_n)/dt), `newmark` (trapezoidal
// rule, beta = 1/4, gamma = 1/2: second order, no numerical damping), `bdf2` (v = (3 d -
// 4 d_n + d_{n-1})/(2 dt), a from v alike; second order, slightly dissipative; its first step
// is bdf1; the same difference formula as the fluid's BDF2 mesh velocity, so the interface
// velocity the coupler hands to the fluid is the mesh velocity there), and `static`
// analysis (equilibrium with the full load in `load_steps` increments per step).
// The scene keys are documented in configs/csm1.yaml and docs/solid.md.
#include <Eigen/Core>
#include <memory>
#include <optional>

#include "fsi/common/scene_schema.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/common/vtk_writer.hpp"
#include "fsi/solid/solid_system.hpp"

namespace fsi::schema {
class Reader;
}

namespace fsi::solid {

enum class TimeScheme { Static, Bdf1, Bdf2, Newmark };

// Contact with the scene's obstacles over the accepted steps (what summary.json reports).
struct ContactStatistics {
  int active_steps = 0;
  double active_time = 0;                     // sum of dt over the steps with contact
  double first_time = -1, last_time = -1;     // first and last step with contact (-1: none)
  double min_gap = 1e300, min_gap_time = -1;  // smallest gap of any accepted step
  Eigen::VectorXd min_gap_point;              // where
  double max_force = 0, max_force_time = -1;  // largest |total contact force|
  Eigen::VectorXd lower, upper;               // bounding box of every active node (empty: none)
  bool active = false;                        // at the last accepted step
  // Adds an accepted step's state.
  void add(const ContactState& s, double time, double dt);
  std::map<std::string, double> report() const;
  void save(StateArchive& state) const;
  void load(const StateArchive& state, int dim);
};

struct Probe {
  std::string name;
  Eigen::VectorXd point;
  int cell = -1;
  Eigen::VectorXd xi;  // natural coordinates in `cell`
};

// The keys of `solid.model: fem` (fem_solid_keys.cpp).
const std::vector<schema::Key>& fem_solid_keys();

class FemSolid : public fsi::SolidModel {
 public:
  FemSolid() = default;
  std::string name() const override { return "fem"; }
  void configure(const ConfigSection& section, const SolidSetup& setup) override;
  InterfaceMeshData interface() const override { return interface_; }
  SolidStepResult solve_step(const StepInfo& info, const Eigen::VectorXd& interface_force) override;
  // Waveform iterations (dynamic analyses): substeps of dt / n from the window's start, the
  // force interpolated in time at each substep's end, linearly for bdf1 and quadratically for
  // the second-order bdf2 and newmark (through the samples nearest in time, the previous
  // window's end included when the coupler sends it).
  bool supports_substeps() const override { return scheme_ != TimeScheme::Static; }
  SolidStepResult solve_window(const StepInfo& info, const Waveform& force, int substeps) override;
  std::map<std::string, double> accept_step(const StepInfo& info) override;
  std::vector<std::string> write_output(const StepInfo& info) override;
  // Checkpoints: the accepted state and the integrator's history (solid.*).
  bool supports_checkpoint() const override { return true; }
  bool supports_interface_mass() const override { return true; }
  // Algorithm 2: M_fs = interface_damping * (M_G (x) I_2) on the interface dofs, replacing the
  // reference-configuration int N^T N of configure().
  void set_interface_mass(const NodalMatrix& m) override;
  void save_state(StateArchive& state) override;
  void load_state(const StateArchive& state) override;
  // Contact statistics ("contact_*") when the scene declares obstacles.
  std::map<std::string, double> diagnostics() const override;
  const ContactStatistics& contact_statistics() const { return contact_stats_; }

  // State access (tests, benchmarks).
  const SolidSystem& system() const { return *system_; }
  SolidSystem& system() { return *system_; }
  const Eigen::VectorXd& displacement() const { return d_; }  // last solve (trial) state
  const Eigen::VectorXd& velocity() const { return v_; }
  TimeScheme scheme() const { return scheme_; }
  Eigen::VectorXd probe_displacement(const Probe& p, const Eigen::VectorXd& d) const;  // dim components
  int dim() const { return mesh_.dim; }
  const std::vector<Probe>& probes() const { return probes_; }
  int last_newton_iterations() const { return last_iterations_; }

 private:
  Eigen::VectorXd external_force(const Eigen::VectorXd& interface_force) const;
  void newton(Eigen::VectorXd& d, const Eigen::VectorXd& f, const TimeTerms& t, const StepInfo& info);
  void configure_obstacles(const schema::Reader& s, const ElasticConstants& constants);
  void configure_supports(const schema::Reader& s);

  SolidMesh mesh_;
  std::unique_ptr<SolidSystem> system_;
  SolidSetup setup_;
  TimeScheme scheme_ = TimeScheme::Static;
  int load_steps_ = 1;
  NewtonOptions newton_;
  Eigen::VectorXd dead_load_;         // gravity + edge tractions
  std::vector<int> interface_nodes_;  // global node ids
  InterfaceMeshData interface_;
  std::vector<Probe> probes_;
  int output_every_ = 1;
  std::optional<PvdSeries> series_;
  // Accepted (n) and trial (n+1) states.
  Eigen::VectorXd d_n_, v_n_, a_n_, f_n_;
  Eigen::VectorXd d_nm1_, v_nm1_;  // step n-1 (bdf2), valid once accepted_steps_ >= 1
  int accepted_steps_ = 0;
  // The step of the last accepted solve (BDF2 takes variable-step coefficients when the next
  // step differs: a fork into other substeps); 0 = not known (uniform steps assumed; a
  // checkpoint without it: the scene's time.dt).
  double dt_n_ = 0, dt_solved_ = 0;
  // solve_window(): the history before the window's last substep, from which accept_step()
  // moves on (the accepted history stays the window's start for the next coupling iteration).
  struct History {
    Eigen::VectorXd d_n, v_n, a_n, f_n, d_nm1, v_nm1;
    int accepted_steps = 0;
    double dt_n = 0;
  };
  std::optional<History> window_end_;
  History history() const { return {d_n_, v_n_, a_n_, f_n_, d_nm1_, v_nm1_, accepted_steps_, dt_n_}; }
  void set_history(const History& h);
  Eigen::VectorXd d_, v_, a_, f_;
  int last_iterations_ = 0;
  bool solved_ = false;
  ContactStatistics contact_stats_;
};

}  // namespace fsi::solid
