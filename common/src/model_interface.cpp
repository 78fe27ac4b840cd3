#include "fsi/common/model_interface.hpp"

#include <fmt/format.h>

#include "fsi/common/interface_geometry.hpp"

namespace fsi {

ModelInterface read_model_interface(const schema::Reader& s, const std::string& measure_key) {
  ModelInterface out;
  const int dim = s.get<int>("dimension");
  if (const auto surface = s.optional_child("surface")) {
    if (dim != 3) s.fail("surface", "a plate interface needs dimension: 3");
    if (s.has(measure_key)) s.fail(measure_key, "is the plate's area when `surface` is given: give one of the two");
    const auto size = surface->vector2("size");
    if (!(size[0] > 0 && size[1] > 0)) surface->fail("size", "edge lengths must be > 0");
    const auto divisions = surface->get<std::vector<int>>("divisions");
    if (divisions[0] < 1 || divisions[1] < 1) surface->fail("divisions", "must be >= 1 each");
    const auto c = surface->vector("centre", 3);
    out.mesh = rectangle_surface(Eigen::Vector3d(c[0], c[1], c[2]), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                 size[0], size[1], divisions[0], divisions[1],
                                 surface->get<std::string>("faces") == "triangle");
    out.measure = size[0] * size[1];
    return out;
  }
  out.measure = s.get<double>(measure_key);
  out.mesh.dimension = dim;
  out.mesh.node_ids = {0};
  out.mesh.coordinates = Eigen::MatrixXd::Zero(1, dim);
  out.mesh.lumped_measure = Eigen::VectorXd::Constant(1, out.measure);
  return out;
}

Eigen::VectorXd ModelInterface::resultant(const Eigen::VectorXd& nodal) const {
  const Eigen::Index d = dimension(), n = static_cast<Eigen::Index>(mesh.nodes());
  if (n == 1) return nodal.head(d);
  Eigen::VectorXd total = Eigen::VectorXd::Zero(d);
  for (Eigen::Index i = 0; i < n; ++i) total += nodal.segment(d * i, d);
  return total;
}

Eigen::VectorXd ModelInterface::uniform(const Eigen::VectorXd& value) const {
  const Eigen::Index d = dimension(), n = static_cast<Eigen::Index>(mesh.nodes());
  Eigen::VectorXd out(d * n);
  for (Eigen::Index i = 0; i < n; ++i) out.segment(d * i, d) = value;
  return out;
}

Eigen::VectorXd ModelInterface::distribute(const Eigen::VectorXd& total) const {
  const Eigen::Index d = dimension(), n = static_cast<Eigen::Index>(mesh.nodes());
  if (n == 1) return total;
  Eigen::VectorXd out(d * n);
  const double sum = mesh.lumped_measure.sum();
  for (Eigen::Index i = 0; i < n; ++i) out.segment(d * i, d) = total * (mesh.lumped_measure[i] / sum);
  return out;
}

}  // namespace fsi
