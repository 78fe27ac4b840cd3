#pragma once
// The coupling interfaces as ParaView series, one file per output step and side:
// vtk/interface_solid.pvd and vtk/interface_fluid.pvd (line cells along the segments, or
// vertices for a point interface; points in the reference configuration, so "Warp By
// Vector" with `displacement` shows the current one). What each side sent and received:
//   solid: displacement, velocity (the solid's), force (the force it solved with),
//          traction_force_mapped, velocity_integral_mapped (the fluid's loads after mapping)
//   fluid: displacement, velocity (the solid's, after mapping: what the fluid received),
//          traction_force, velocity_integral (what the fluid sent, before mapping)
// Comparing sum(force) on both sides, or the fields in ParaView, checks a mapping.
#include <Eigen/Core>
#include <filesystem>

#include "fsi/common/solver_model.hpp"
#include "fsi/common/vtk_writer.hpp"

namespace fsi::coupling {

struct InterfaceFields {
  Eigen::VectorXd solid_displacement, solid_velocity, solid_force;  // 2 n_s each
  Eigen::VectorXd traction_mapped, velocity_integral_mapped;        // 2 n_s each
  Eigen::VectorXd fluid_displacement, fluid_velocity;               // 2 n_f each
  Eigen::VectorXd traction_force, velocity_integral;                // 2 n_f each
};

class InterfaceOutput {
 public:
  InterfaceOutput(const std::filesystem::path& vtk_dir, const InterfaceMeshData& solid, const InterfaceMeshData& fluid,
                  VtkFormat format = VtkFormat::Binary);
  void write(double time, int step, const InterfaceFields& fields);

 private:
  VtkGrid solid_grid_, fluid_grid_;
  PvdSeries solid_series_, fluid_series_;
};

}  // namespace fsi::coupling
