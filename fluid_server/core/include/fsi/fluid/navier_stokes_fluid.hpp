#pragma once
// fsi::FluidModel for `fluid: {model: fem, ...}`: reads the scene keys (documented in
// configs/dfg_2d1.yaml and docs/fluid.md), meshes the .geo with the gmsh CLI (cached),
// runs FlowSolver with fluid.element p1p1 or p2p1, moves the mesh by a harmonic extension of the interface
// displacement, and reports drag/lift (consistent reactions), pressure probes, VTK.
//
// Call order (fsi::FluidModel): configure -> interface -> {solve_step ... accept_step} -> write_output.
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fsi/common/gmsh_mesher.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/solver_model.hpp"
#include "fsi/common/vtk_writer.hpp"
#include "fsi/fluid/mesh_motion.hpp"
#include "fsi/fluid/navier_stokes_solver.hpp"

namespace fsi::schema {
class Reader;
}

namespace fsi::fluid {

// Meshing a .geo at run time (cached): fsi/common/gmsh_mesher.hpp.
using fsi::mesh_geo;

// The keys of `fluid.model: fem` (navier_stokes_keys.cpp).
const std::vector<schema::Key>& navier_stokes_keys();

class NavierStokesFluid : public FluidModel {
 public:
  NavierStokesFluid();
  ~NavierStokesFluid() override;
  std::string name() const override { return "fem"; }
  void configure(const ConfigSection& section, const FluidSetup& setup) override;
  InterfaceMeshData interface() const override;
  FluidLoads initial_loads(const Eigen::VectorXd& interface_displacement,
                           const Eigen::VectorXd& interface_velocity) override;
  FluidLoads solve_step(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                        const Eigen::VectorXd& interface_velocity) override;
  // The explicit Robin-Neumann coupling's interface condition (FlowSolver::solve with a
  // RobinCondition; 2D, both elements).
  bool supports_robin() const override { return solver_ != nullptr; }
  FluidLoads solve_robin(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                         const RobinCondition& robin) override;
  // Waveform iterations (fluid.substeps > 1; BDF1 and BDF2, 2D and 3D): the window in substeps
  // from the accepted state, the interface displacement and velocity interpolated in time at each
  // substep's end (linearly for BDF1, by parabolas for BDF2), the substeps inside the window
  // accepted (flow history, mesh motion), every substep's loads returned. The window's start is
  // kept in memory until accept_step(): a repeated call (the next coupling iteration) restarts
  // from it. The linear solver's factors stay in use across substeps and calls. With
  // interface.penalty_geometry step_start the penalty term (and M_f) is on the window's start
  // for every substep (the solid's damping M_G is one per window). A mesh that folds inside a
  // window is an error (remeshing happens between windows, in accept_step()).
  bool supports_substeps() const override;
  FluidLoads solve_window(const StepInfo& info, const Waveform& displacement, const Waveform& velocity,
                          int substeps) override;
  std::map<std::string, double> accept_step(const StepInfo& info) override;
  std::vector<std::string> write_output(const StepInfo& info) override;

  // Checkpoints (after accept_step): the flow solver's state ("flow.*": velocity, pressure and
  // BDF history, positions, step sizes and counts, interface velocity, "flow.lu.ordering"),
  // the mesh motion's ("mesh.*", when the scene has an interface), and this model's
  // ("fluid.last_interface_displacement", "fluid.factorisations", "fluid.solves"). Saving
  // drops the LU factors: the next solve refactorises, in the saved model as in a restored one.
  // Timings are not restored (they are this process's).
  bool supports_checkpoint() const override { return true; }
  void save_state(StateArchive& state) override;
  void load_state(const StateArchive& state) override;

  // For tests and benchmarks.
  const FlowSolver& solver() const { return *solver_; }
  FlowSolver& solver() { return *solver_; }
  const StepReport& last_report() const { return last_report_; }

  // Cumulative seconds: "mesh_motion" (extension), "assembly", "factorisation", "linear_solve"
  // (triangular solves and Krylov iterations), "step" (all of them, per solve call).
  std::map<std::string, double> timings() const override {
    std::map<std::string, double> t{{"mesh_motion", motion_    ? motion_->seconds()
                                                    : motion3_ ? motion3_->seconds()
                                                               : 0.0},
                                    {"assembly", assembly_seconds_},
                                    {"factorisation", factor_seconds_},
                                    {"linear_solve", linear_solve_seconds_},
                                    {"step", solve_seconds_}};
    if (remeshes_ > 0) t["remesh"] = remesh_seconds_, t["remeshes"] = remeshes_;  // "remeshes": a count
    if (remesh_retries_ > 0) t["remesh_retries"] = remesh_retries_;  // of those, steps solved again (a count)
    return t;
  }
  // Unknowns, mesh nodes and triangles (summary.json of standalone runs).
  std::map<std::string, double> sizes() const override {
    if (solver3_)
      return {{"dofs", solver3_->dofs()},
              {"nodes", solver3_->mesh().node_count()},
              {"tetrahedra", solver3_->mesh().cell_count()}};
    if (!solver_) return {};
    return {{"dofs", solver_->dofs()},
            {"nodes", solver_->mesh().node_count()},
            {"triangles", solver_->mesh().triangle_count()}};
  }

 private:
  struct ForceProbe {
    std::string name;
    std::vector<std::string> groups;
    double coefficient_scale = 0;  // 2 / (rho U^2 L), 0 = no coefficients
  };
  FluidSetup setup_;
  std::string element_;  // fluid.element: p1p1 or p2p1
  // fluid.dimension 3: the same FlowSolver on tetrahedra, with a Nitsche interface of 6-node faces.
  std::unique_ptr<FlowSolver3> solver3_;
  std::vector<std::pair<std::string, Eigen::Vector3d>> pressure_probes3_;
  void configure3(const schema::Reader& section);
  void configure_mesh_motion3(const schema::Reader& iface);
  Eigen::MatrixX3d positions3(const Eigen::VectorXd& interface_displacement);
  std::unique_ptr<MeshMotion3> motion3_;
  std::map<std::string, double> probes3();
  std::unique_ptr<FlowSolver> solver_;
  FluidMesh motion_mesh_;  // the mesh the extension runs on (P2: the vertices, or 4 linear triangles per element)
  bool motion_on_vertices_ = false;
  std::vector<int> motion_vertex_index_;  // P2 on vertices: interface index of each moving vertex
  // configure's parts (the scene keys they read: navier_stokes_fluid.cpp).
  std::vector<std::string> add_boundary_conditions(const schema::Reader& section, const std::string& msh);
  void configure_mesh_motion(const schema::Reader& section, const std::vector<std::string>& groups,
                             const std::vector<std::string>& fixed_groups);
  void configure_output(const schema::Reader& section, double density);
  void configure_vtk(const schema::Reader& section);  // fluid.output.vtk_every (both dimensions)
  void build_mesh_motion();
  // Remeshing (fluid.remesh; remesh.hpp).
  struct RemeshSettings {
    bool enabled = false;
    double min_quality = 0.1;          // remesh when the minimum scaled Jacobian falls below
    double min_curved_jacobian = 0.3;  // P2: or the curved Jacobian (relative) below
    std::vector<int> at_steps;         // forced remeshes after these steps (tests)
  } remesh_;
  void read_remesh(const schema::Reader& section, bool moving);
  void remesh(const StepInfo& info, const std::string& why);
  std::unique_ptr<FlowSolver> make_solver(FluidMesh mesh, const FlowParameters& params) const;
  void watch(FlowSolver& solver) const;
  void save_remeshed(StateArchive& state) const;
  void load_remeshed(const StateArchive& state);
  static FluidMesh mesh_from_state(const StateArchive& state);
  void load_initial_state(const std::filesystem::path& file);
  std::vector<std::function<void(FlowSolver&)>> conditions_;  // the scene's conditions, for a new solver
  std::vector<std::string> interface_groups_, fixed_groups_;
  MeshMotionOptions motion_options_;
  FluidMesh original_mesh_;        // the scene's mesh (checkpoints from before a remesh)
  Eigen::VectorXd remesh_offset_;  // the interface displacement at the last remesh
  double remesh_quality_ = 1.0;    // the quality the last remesh reached
  Eigen::VectorXd remesh_size_;    // the target size per vertex (the scene mesh's, carried on)
  int remeshes_ = 0;
  double remesh_seconds_ = 0;
  Eigen::VectorXd motion_input(const Eigen::VectorXd& interface_displacement) const;
  Eigen::MatrixX2d extend(const Eigen::VectorXd& interface_displacement) const;  // every node
  std::unique_ptr<MeshMotion> motion_;
  std::vector<ForceProbe> forces_;
  std::vector<std::pair<std::string, Eigen::Vector2d>> pressure_probes_;
  std::vector<std::pair<std::string, std::pair<std::string, std::string>>> pressure_differences_;
  int vtk_every_ = -1;  // -1: whenever asked
  PvdSeries vtk_;
  StepReport last_report_;
  double solve_seconds_ = 0;
  double assembly_seconds_ = 0, factor_seconds_ = 0, linear_solve_seconds_ = 0;
  std::chrono::steady_clock::time_point start_, last_log_;
  int solves_ = 0;
  int factorisations_ = 0;                           // cumulative
  int linear_iterations_ = 0;                        // cumulative Krylov iterations (3D probe)
  Eigen::VectorXd last_interface_displacement_;      // of the last solve (for the mesh motion's accept)
  Eigen::VectorXd accepted_interface_displacement_;  // of the last accepted step (a remesh's new offset)
  int retried_step_ = -1;                            // the step whose folding motion was remeshed and solved again
  int remesh_retries_ = 0;                           // how many steps were (a count, also in checkpoints)
  // An open waveform window (solve_window until accept_step): its start.
  struct WindowStart;
  std::unique_ptr<WindowStart> window_;
  bool in_window_ = false;  // inside solve_window's substeps (no remeshing retry)
  void restore_window_start();
  void close_window();
  void hold_penalty_interface(bool hold);
  void accept_substep();
  void solve_on_mesh(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                     const Eigen::VectorXd& interface_velocity, const RobinCondition* robin);
  // solve_step and solve_robin (robin: null = Nitsche's terms with interface_velocity).
  FluidLoads solve(const StepInfo& info, const Eigen::VectorXd& interface_displacement,
                   const Eigen::VectorXd& interface_velocity, const RobinCondition* robin);
};

}  // namespace fsi::fluid
