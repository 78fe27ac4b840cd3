#pragma once
// The physics-side contract of a solver server: what the coupler needs from a solid or a
// fluid, in Eigen types. The service layer (protocol/) translates wire messages into
// these calls; the solvers know nothing of sockets or protobuf.
//
// Interface vectors are interleaved per node: [x0, y0, x1, y1, ...] in 2D,
// [x0, y0, z0, x1, ...] in 3D (InterfaceMeshData::dimension).
//
// Call order (enforced by the service layer):
//   configure() -> interface() -> { solve_step(k = 1..) ... accept_step() } ... -> write_output()
// Checkpoints (optional, supports_checkpoint()): save_state() after an accepted step holds
// everything the next step depends on; load_state() on a freshly configured model (same
// scene) makes it continue exactly as the saved one would have, bit for bit.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "fsi/common/config.hpp"
#include "fsi/common/state.hpp"
#include "fsi/common/vtk_writer.hpp"
#include "fsi/common/waveform.hpp"

namespace fsi {

// A failure of the solver itself (no convergence, tangled mesh, singular matrix).
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A model asked for a checkpoint it cannot write.
class CheckpointUnsupported : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
[[noreturn]] inline void unsupported_checkpoint(const std::string& model) {
  throw CheckpointUnsupported("model '" + model + "' does not support checkpoints");
}

// A scalar matrix on interface nodes that acts on every component alike (an interface
// mass int N_i N_j dgamma); 0 x 0 = not given.
using NodalMatrix = Eigen::SparseMatrix<double>;

// (M (x) I_d) v for interleaved v = [x0, y0, (z0,) x1, ...]; d = v.size() / m.rows().
inline Eigen::VectorXd apply_nodal(const NodalMatrix& m, const Eigen::VectorXd& v) {
  Eigen::VectorXd out(v.size());
  if (m.rows() == 0 || v.size() == 2 * m.rows()) {  // the 2D path, fixed-size as always
    const Eigen::Map<const Eigen::Matrix<double, 2, Eigen::Dynamic>> V(v.data(), 2, v.size() / 2);
    Eigen::Map<Eigen::Matrix<double, 2, Eigen::Dynamic>> O(out.data(), 2, v.size() / 2);
    O = (m * V.transpose()).transpose();
    return out;
  }
  const Eigen::Index d = v.size() / m.rows();
  const Eigen::Map<const Eigen::MatrixXd> V(v.data(), d, m.rows());
  Eigen::Map<Eigen::MatrixXd> O(out.data(), d, m.rows());
  O = (m * V.transpose()).transpose();
  return out;
}

// One face of a 3D interface: local node indices in gmsh order. 3 = linear triangle,
// 6 = quadratic triangle, 4 = bilinear quadrilateral, 8 = serendipity, 9 = biquadratic.
struct InterfaceFace {
  std::vector<int> nodes;
};

struct InterfaceMeshData {
  int dimension = 2;  // 2: segments, 2 values per node; 3: faces, 3 values per node
  std::vector<std::int64_t> node_ids;
  Eigen::MatrixXd coordinates;               // reference configuration, n x dimension
  std::vector<std::array<int, 2>> segments;  // 2D: local indices; empty for a point interface
  std::vector<InterfaceFace> faces;          // 3D: local indices; empty for a point interface
  Eigen::VectorXd lumped_measure;            // used when there are no segments/faces (size n)
  Eigen::VectorXd initial_displacement;      // dimension * n, or empty = zero
  Eigen::VectorXd initial_velocity;          // dimension * n, or empty = zero
  double mass_per_area = 0;                  // a solid's m_s / |Gamma| (coupling.robin_auto); 0 = unknown
  std::size_t nodes() const { return static_cast<std::size_t>(coordinates.rows()); }
  // Values of an interface vector: dimension per node.
  std::size_t values() const { return nodes() * static_cast<std::size_t>(dimension); }
  // A point interface: no segments or faces, the measure lumped per node.
  bool points_only() const { return segments.empty() && faces.empty(); }
};

struct StepInfo {
  double time = 0;  // t_{n+1}
  double dt = 0;
  int step = 0;       // n+1
  int iteration = 0;  // coupling iteration k (1-based); 0 when standalone
};

struct SolidSetup {
  double dt = 0;
  double end_time = 0;
  double interface_damping = 0;              // gamma_N1 for Algorithm 2, else 0
  std::filesystem::path output_dir;          // empty = write nothing
  VtkFormat vtk_format = VtkFormat::Binary;  // time.vtk_format
};

struct SolidStepResult {
  Eigen::VectorXd interface_displacement;  // dimension * n (at the window's end)
  Eigen::VectorXd interface_velocity;      // dimension * n
  int newton_iterations = 0;
  // solve_window(): the interface state at the end of every substep, concatenated (substeps
  // blocks of dimension * n, the last the window's end); empty = one step.
  Eigen::VectorXd displacement_samples, velocity_samples;
};

// Inside a long solve, after each nonlinear iteration, a short text for whoever runs the model
// (a standalone run prints it every 2 s, so a long step is not silent). Unset: nothing happens.
class IterationReporting {
 public:
  void on_iteration(std::function<void(const std::string&)> observer) { on_iteration_ = std::move(observer); }

 protected:
  void report_iteration(const std::string& text) const {
    if (on_iteration_) on_iteration_(text);
  }

 private:
  std::function<void(const std::string&)> on_iteration_;
};

class SolidModel : public IterationReporting {
 public:
  virtual ~SolidModel() = default;
  virtual std::string name() const = 0;
  virtual bool supports_interface_damping() const { return true; }
  // Algorithm 2 with a consistent damping: before a solve, the coupler may give the interface
  // mass M_G = H^T M_f H (n x n, the fluid's current interface mapped to the solid's nodes);
  // the model then uses M_fs = interface_damping * M_G until the next one. A model without
  // it keeps its own int N^T N (the gamma_N1 terms then cancel only where the two agree).
  virtual bool supports_interface_mass() const { return false; }
  virtual void set_interface_mass(const NodalMatrix& /*m*/) {}
  // Reads this solver's section of the scene; must read every key it accepts.
  virtual void configure(const ConfigSection& section, const SolidSetup& setup) = 0;
  virtual InterfaceMeshData interface() const = 0;
  // Solves step n+1 for the nodal interface force F^(k)_{n+1} (dimension * n). Repeated calls for the
  // same step restart from the last accepted state.
  virtual SolidStepResult solve_step(const StepInfo& info, const Eigen::VectorXd& interface_force) = 0;
  // Waveform iterations (solid.substeps > 1): the window (info.time - info.dt, info.time] in
  // `substeps` steps of info.dt / substeps from the last accepted state, each with the force
  // interpolated in time (Waveform::at) at its end; returns every substep's interface state
  // (SolidStepResult's samples). Repeated calls restart from the window's start; accept_step()
  // accepts the window's end.
  virtual bool supports_substeps() const { return false; }
  virtual SolidStepResult solve_window(const StepInfo& /*info*/, const Waveform& /*force*/, int /*substeps*/) {
    throw std::logic_error("solid '" + name() + "' does not take substeps");
  }
  // Makes the last solve the new accepted state; returns named probes.
  virtual std::map<std::string, double> accept_step(const StepInfo& info) = 0;
  virtual std::vector<std::string> write_output(const StepInfo& info) { return {}; }
  // False: write_output() is never called (a remote server without supports_output).
  virtual bool supports_output() const { return true; }
  // Cumulative wall seconds by category (e.g. "assembly", "linear_solve"), reported in
  // the run summary. Optional.
  virtual std::map<std::string, double> timings() const { return {}; }
  // Problem size for summary.json after configure() (e.g. "dofs", "nodes", "elements").
  virtual std::map<std::string, double> sizes() const { return {}; }
  // Statistics of the run so far, after accept_step(), for summary.json's "solid_diagnostics"
  // (e.g. contact: how long, where, the smallest gap). Part of the checkpointed state. Optional.
  virtual std::map<std::string, double> diagnostics() const { return {}; }
  // Checkpoints: the state after the last accepted step; see the call order above.
  virtual bool supports_checkpoint() const { return false; }
  virtual void save_state(StateArchive& /*state*/) { unsupported_checkpoint(name()); }
  virtual void load_state(const StateArchive& /*state*/) { unsupported_checkpoint(name()); }
  // The state as opaque bytes (what the coupler stores); a remote model forwards these to
  // its server, an in-process one serialises save_state().
  virtual std::string save_checkpoint(int /*step*/, double /*time*/) {
    StateArchive s;
    save_state(s);
    return s.serialize();
  }
  virtual void load_checkpoint(int step, double /*time*/, const std::string& bytes) {
    load_state(StateArchive::parse(bytes, name() + " checkpoint of step " + std::to_string(step)));
  }
};

struct FluidSetup {
  double dt = 0;
  double end_time = 0;
  double nitsche_penalty = 0;    // gamma_N1
  double nitsche_symmetry = -1;  // gamma_N2
  std::filesystem::path output_dir;
  VtkFormat vtk_format = VtkFormat::Binary;  // time.vtk_format
};

struct FluidLoads {
  Eigen::VectorXd traction_force;     // f_sigma = int N^T sigma n dgamma (dimension * n)
  Eigen::VectorXd velocity_integral;  // f_v = int N^T v_f dgamma (dimension * n)
  int nonlinear_iterations = 0;
  NodalMatrix interface_mass;  // M_f (n x n, current configuration; f_v = M_f v_f); 0 x 0 = not given
  // solve_window(): traction_force and velocity_integral at the end of every substep,
  // concatenated (the last = the window's end, also in the two above); empty = one step.
  Eigen::VectorXd traction_samples, velocity_integral_samples;
};

// The explicit Robin-Neumann scheme's interface condition on the fluid (coupling.scheme:
// robin-neumann), in place of the velocity Nitsche's method imposes: at every interface node j
//   f_sigma_j + A_j v_f,j = A_j v*_j + f*_j,   A_j = coefficient_j x (node j's lumped measure),
// f_sigma the fluid's interface traction force (FluidLoads::traction_force) and v_f its
// interface velocity, both unknown. The coefficient is the solid's interface inertia (its mass
// per interface measure over dt); v* and f* are extrapolated from the accepted steps.
struct RobinCondition {
  Eigen::VectorXd coefficient;  // per interface node, per unit measure (kg / (m^2 s) in 3D)
  Eigen::VectorXd velocity;     // v* (dimension x nodes, interleaved)
  Eigen::VectorXd traction;     // f* (nodal forces, as traction_force)
};

class FluidModel : public IterationReporting {
 public:
  virtual ~FluidModel() = default;
  virtual std::string name() const = 0;
  virtual void configure(const ConfigSection& section, const FluidSetup& setup) = 0;
  virtual InterfaceMeshData interface() const = 0;
  // Loads of the initial state for the given interface state (for the predictor F_0).
  virtual FluidLoads initial_loads(const Eigen::VectorXd& interface_displacement,
                                   const Eigen::VectorXd& interface_velocity) = 0;
  // Moves the mesh to the interface displacement, imposes the interface velocity by
  // Nitsche's method, solves step n+1 and returns the interface loads.
  virtual FluidLoads solve_step(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                                const Eigen::VectorXd& interface_velocity) = 0;
  // Waveform iterations (fluid.substeps > 1): the window in `substeps` steps of info.dt /
  // substeps from the last accepted state, the interface displacement and velocity
  // interpolated in time at each substep's end; returns every substep's loads (FluidLoads'
  // samples). Repeated calls restart from the window's start.
  virtual bool supports_substeps() const { return false; }
  virtual FluidLoads solve_window(const StepInfo& /*info*/, const Waveform& /*displacement*/,
                                  const Waveform& /*velocity*/, int /*substeps*/) {
    throw std::logic_error("fluid '" + name() + "' does not take substeps");
  }
  // The same step with the Robin condition on the interface instead (supports_robin()).
  virtual bool supports_robin() const { return false; }
  virtual FluidLoads solve_robin(const StepInfo& /*info*/, const Eigen::VectorXd& /*interface_displacement*/,
                                 const RobinCondition& /*robin*/) {
    throw std::logic_error("fluid '" + name() + "' does not take a Robin interface condition");
  }
  virtual std::map<std::string, double> accept_step(const StepInfo& info) = 0;
  // Statistics of the run so far (summary.json's "fluid_diagnostics"); see SolidModel. Optional.
  virtual std::map<std::string, double> diagnostics() const { return {}; }
  virtual std::vector<std::string> write_output(const StepInfo& info) { return {}; }
  // False: write_output() is never called (a remote server without supports_output).
  virtual bool supports_output() const { return true; }
  // Cumulative wall seconds by category (e.g. "mesh_motion", "assembly", "linear_solve").
  virtual std::map<std::string, double> timings() const { return {}; }
  // Problem size for summary.json after configure() (e.g. "dofs", "nodes", "triangles").
  virtual std::map<std::string, double> sizes() const { return {}; }
  // Checkpoints: the state after the last accepted step; see the call order above.
  virtual bool supports_checkpoint() const { return false; }
  virtual void save_state(StateArchive& /*state*/) { unsupported_checkpoint(name()); }
  virtual void load_state(const StateArchive& /*state*/) { unsupported_checkpoint(name()); }
  // The state as opaque bytes (what the coupler stores); a remote model forwards these to
  // its server, an in-process one serialises save_state().
  virtual std::string save_checkpoint(int /*step*/, double /*time*/) {
    StateArchive s;
    save_state(s);
    return s.serialize();
  }
  virtual void load_checkpoint(int step, double /*time*/, const std::string& bytes) {
    load_state(StateArchive::parse(bytes, name() + " checkpoint of step " + std::to_string(step)));
  }
};

}  // namespace fsi
