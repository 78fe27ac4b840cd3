#pragma once
// The interface of the point models (solid.model: sdof, fluid.model: surrogate) in 2D or 3D:
// one node at the origin with a lumped measure, or, in 3D, a rigid flat plate (a rectangle
// parallel to the plane z = 0, divided into quadrilaterals or triangles) that moves as one body. Its keys
// are shared by both models so that a scene describes the two sides the same way.
#include <vector>

#include "fsi/common/scene_reader.hpp"
#include "fsi/common/scene_schema.hpp"
#include "fsi/common/solver_model.hpp"

namespace fsi {

// `dimension` and `surface` (declared by both point models).
std::vector<schema::Key> model_interface_keys();

struct ModelInterface {
  InterfaceMeshData mesh;  // node_ids, coordinates, faces, lumped_measure, dimension
  double measure = 1;      // the total measure (interface_measure, or the plate's area)
  int dimension() const { return mesh.dimension; }
  // The sum over the nodes of an interleaved vector: the resultant force on a rigid body.
  Eigen::VectorXd resultant(const Eigen::VectorXd& nodal) const;
  // One value per component, the same at every node: a rigid body's motion.
  Eigen::VectorXd uniform(const Eigen::VectorXd& value) const;
  // Each node's share of a resultant force, by its lumped measure.
  Eigen::VectorXd distribute(const Eigen::VectorXd& total) const;
};

// Reads dimension, surface and `measure_key` (the model's interface_measure) from `s`.
ModelInterface read_model_interface(const schema::Reader& s, const std::string& measure_key);

}  // namespace fsi
