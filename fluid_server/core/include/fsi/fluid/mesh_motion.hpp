#pragma once
// Mesh motion: extends the interface displacement into the fluid mesh.
//
//  - method `harmonic`: Laplace extension per component; `elastic`: pseudo-solid linear
//    elasticity (keeps element shapes better near rotating corners and thin flaps).
//  - Jacobian-based stiffening: element stiffness ~ (A_mean / A_e)^stiffening, so small
//    elements near the body move almost rigidly.
//  - `incremental: false`: one operator on the reference mesh (linear in the displacement,
//    factorised once). `incremental: true`: after each accepted step the operator is
//    rebuilt on the current mesh (areas and shapes of the deformed elements) and the next
//    step extends only the displacement increment: large cumulative deformations (bending
//    flaps, rotating beams) stay valid far longer, for one sparse factorisation per step.
//
//   MeshMotion motion(mesh, interface_nodes, fixed_nodes, options);
//   Eigen::MatrixX2d x = mesh.nodes + motion.extend(interface_displacement);  // any iteration
//   motion.accept(interface_displacement);                                     // step accepted
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "fsi/common/state.hpp"
#include "fsi/fluid/mesh.hpp"

namespace fsi::fluid {

struct MeshMotionOptions {
  enum class Method { Harmonic, Elastic };
  Method method = Method::Harmonic;
  double stiffening = 1.0;     // exponent of (A_mean / A_e)
  bool incremental = false;    // rebuild the operator on the deformed mesh after each step
  double poisson_ratio = 0.3;  // elastic only
};

class MeshMotion {
 public:
  MeshMotion(const FluidMesh& mesh, std::vector<int> moving_nodes, std::vector<int> fixed_nodes,
             MeshMotionOptions options = {});
  MeshMotion(const FluidMesh& mesh, std::vector<int> moving_nodes, std::vector<int> fixed_nodes, double stiffening)
      : MeshMotion(mesh, std::move(moving_nodes), std::move(fixed_nodes),
                   MeshMotionOptions{MeshMotionOptions::Method::Harmonic, stiffening, false}) {}
  ~MeshMotion();
  // Displacement of every node from the reference mesh (n x 2) for the moving nodes' total
  // displacement from the reference (interleaved x, y).
  Eigen::MatrixX2d extend(const Eigen::VectorXd& moving_displacement) const;
  // The step with this moving displacement was accepted (incremental: rebuild the operator
  // on the mesh it produced). Throws fsi::SolverError if that mesh has an inverted element.
  void accept(const Eigen::VectorXd& moving_displacement);
  double seconds() const;  // wall time spent in extend() and accept()

  // Checkpoints: the mesh of the last accepted step (prefix + "base_displacement", every node,
  // column-major, and "base_moving", the moving nodes' displacement there). The extension is
  // a direct solve (no initial guess); incremental: load_state() rebuilds the operator on that
  // mesh, as accept() did. fsi::StateError (naming the entry) for another mesh.
  void save_state(StateArchive& state, const std::string& prefix) const;
  void load_state(const StateArchive& state, const std::string& prefix);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fsi::fluid
