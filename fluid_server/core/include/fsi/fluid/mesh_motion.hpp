#pragma once
// Mesh motion: harmonic (Laplace) extension of the interface displacement into the fluid
// mesh, with Jacobian-based stiffening (element stiffness ~ (A_ref / A_e)^stiffening, so
// small elements near the body move almost rigidly). Linear in the displacement: the
// matrix is factorised once on the reference mesh.
//   MeshMotion motion(mesh, interface_nodes, fixed_nodes);
//   Eigen::MatrixX2d x = mesh.nodes + motion.extend(interface_displacement);
#include <Eigen/Core>

#include <memory>
#include <vector>

#include "fsi/fluid/mesh.hpp"

namespace fsi::fluid {

class MeshMotion {
 public:
  MeshMotion(const FluidMesh& mesh, std::vector<int> moving_nodes, std::vector<int> fixed_nodes, double stiffening = 1.0);
  ~MeshMotion();
  // Displacement of every node (n x 2) for the moving nodes' displacement (interleaved).
  Eigen::MatrixX2d extend(const Eigen::VectorXd& moving_displacement) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fsi::fluid
