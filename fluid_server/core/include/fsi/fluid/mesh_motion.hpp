#pragma once
// Mesh motion: extends the interface displacement into the fluid mesh, in 2D (triangles,
// MeshMotion) and 3D (tetrahedra, MeshMotion3): one implementation, BasicMeshMotion<Dim>,
// with the element (triangle / tetrahedron) as the only dimension-dependent part.
//
//  - method `harmonic`: Laplace extension per component; `elastic`: pseudo-solid linear
//    elasticity (keeps element shapes better near rotating corners and thin flaps).
//  - Jacobian-based stiffening: element stiffness ~ (A_mean / A_e)^stiffening (volumes in 3D),
//    so small elements near the body move almost rigidly.
//  - `incremental: false`: one operator on the reference mesh (linear in the displacement,
//    factorised once). `incremental: true`: after each accepted step the operator is
//    rebuilt on the current mesh (areas and shapes of the deformed elements) and the next
//    step extends only the displacement increment: large cumulative deformations (bending
//    flaps, rotating beams) stay valid far longer, for one sparse factorisation per step.
//  - The extension is P1 on the vertices (the cells' corners). Quadratic meshes (6-node
//    triangles, 10-node tetrahedra): the edge midpoints that are neither moving nor fixed
//    follow their edge's vertices (the mean: edges stay straight inside); moving midpoints
//    take their prescribed displacement (a curved interface follows the solid), fixed ones stay.
//    (The 2D fluid passes a linear mesh: its vertices or the 4-triangle refinement.)
//
//   MeshMotion motion(mesh, interface_nodes, fixed_nodes, options);
//   Eigen::MatrixX2d x = mesh.nodes + motion.extend(interface_displacement);  // any iteration
//   motion.accept(interface_displacement);                                     // step accepted
//   MeshMotion3 motion3(tet_mesh, interface_nodes, fixed_nodes, options);
//   Eigen::MatrixX3d x3 = motion3.positions(interface_displacement);          // (x, y, z) per node
#include <Eigen/Core>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "fsi/common/state.hpp"
#include "fsi/fluid/mesh.hpp"
#include "fsi/fluid/tet_mesh.hpp"

namespace fsi::fluid {

struct MeshMotionOptions {
  enum class Method { Harmonic, Elastic };
  Method method = Method::Harmonic;
  double stiffening = 1.0;     // exponent of (A_mean / A_e)
  bool incremental = false;    // rebuild the operator on the deformed mesh after each step
  double poisson_ratio = 0.3;  // elastic only
};

template <int Dim>
class BasicMeshMotion {
 public:
  using Mesh = std::conditional_t<Dim == 2, FluidMesh, TetMesh>;
  using Nodes = Eigen::Matrix<double, Eigen::Dynamic, Dim>;

  // Keeps a pointer to `mesh`. moving_nodes: the interface (their displacement is prescribed
  // by extend()); fixed_nodes: held at zero displacement.
  BasicMeshMotion(const Mesh& mesh, std::vector<int> moving_nodes, std::vector<int> fixed_nodes,
                  MeshMotionOptions options = {});
  BasicMeshMotion(const Mesh& mesh, std::vector<int> moving_nodes, std::vector<int> fixed_nodes, double stiffening)
      : BasicMeshMotion(mesh, std::move(moving_nodes), std::move(fixed_nodes),
                        MeshMotionOptions{MeshMotionOptions::Method::Harmonic, stiffening, false}) {}
  ~BasicMeshMotion();
  // Displacement of every node from the reference mesh (n x Dim) for the moving nodes' total
  // displacement from the reference (interleaved x, y[, z]; Dim per moving node).
  Nodes extend(const Eigen::VectorXd& moving_displacement) const;
  // The node positions: the reference mesh plus extend().
  Nodes positions(const Eigen::VectorXd& moving_displacement) const;
  // The step with this moving displacement was accepted (incremental: rebuild the operator
  // on the mesh it produced). Throws fsi::SolverError if that mesh has an inverted element.
  void accept(const Eigen::VectorXd& moving_displacement);
  double seconds() const;  // wall time spent in extend() and accept()
  const std::vector<int>& moving_nodes() const;

  // Checkpoints: the mesh of the last accepted step (prefix + "base_displacement", every node,
  // column-major, and "base_moving", the moving nodes' displacement there). The extension is
  // a direct solve (no initial guess); incremental: load_state() rebuilds the operator on that
  // mesh, as accept() did. fsi::StateError (naming the entry) for another mesh.
  void save_state(StateArchive& state, const std::string& prefix) const;
  void load_state(const StateArchive& state, const std::string& prefix);

  // Waveform windows: the accepted mesh (the incremental state and its factorised operator) as a
  // snapshot in memory, and back, without a refactorisation (accept() after a snapshot factorises
  // into a new operator, leaving the snapshot's as it was).
  struct Snapshot;
  std::shared_ptr<const Snapshot> snapshot() const;
  void restore(const Snapshot& snapshot);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

using MeshMotion = BasicMeshMotion<2>;   // triangles (the 2D fluid)
using MeshMotion3 = BasicMeshMotion<3>;  // 4- or 10-node tetrahedra (the 3D fluid)

extern template class BasicMeshMotion<2>;
extern template class BasicMeshMotion<3>;

}  // namespace fsi::fluid
