#include "fsi/coupling/interface_output.hpp"

#include <stdexcept>
#include <string>

namespace fsi::coupling {
namespace {

VtkGrid grid_of(const InterfaceMeshData& mesh) {
  VtkGrid g;
  g.points = mesh.coordinates;
  if (mesh.points_only()) {
    for (int i = 0; i < static_cast<int>(mesh.nodes()); ++i) {
      g.cells.push_back({i});
      g.cell_types.push_back(VtkCellType::Vertex);
    }
  } else if (!mesh.faces.empty()) {
    for (const auto& f : mesh.faces) {
      g.cells.push_back(f.nodes);
      switch (f.nodes.size()) {
        case 3:
          g.cell_types.push_back(VtkCellType::Triangle);
          break;
        case 4:
          g.cell_types.push_back(VtkCellType::Quad);
          break;
        case 6:
          g.cell_types.push_back(VtkCellType::QuadraticTriangle);
          break;
        case 8:
          g.cell_types.push_back(VtkCellType::QuadraticQuad);
          break;
        default:
          g.cell_types.push_back(VtkCellType::BiquadraticQuad);
          break;
      }
    }
  } else {
    for (const auto& s : mesh.segments) {
      g.cells.push_back({s[0], s[1]});
      g.cell_types.push_back(VtkCellType::Line);
    }
  }
  return g;
}

// Interleaved values (d per node) as an n x d matrix.
Eigen::MatrixXd nodal(const Eigen::VectorXd& v, Eigen::Index n, const char* name) {
  if (n == 0 || v.size() % n != 0 || v.size() / n < 2 || v.size() / n > 3)
    throw std::invalid_argument(std::string("interface output: '") + name + "' has the wrong size");
  const Eigen::Index d = v.size() / n;
  return Eigen::Map<const Eigen::MatrixXd>(v.data(), d, n).transpose();
}

}  // namespace

InterfaceOutput::InterfaceOutput(const std::filesystem::path& vtk_dir, const InterfaceMeshData& solid,
                                 const InterfaceMeshData& fluid, VtkFormat format)
    : solid_grid_(grid_of(solid)),
      fluid_grid_(grid_of(fluid)),
      solid_series_(vtk_dir, "interface_solid", format),
      fluid_series_(vtk_dir, "interface_fluid", format) {}

void InterfaceOutput::write(double time, int step, const InterfaceFields& f) {
  const Eigen::Index ns = solid_grid_.points.rows(), nf = fluid_grid_.points.rows();
  auto& s = solid_grid_.point_data;
  s["displacement"] = nodal(f.solid_displacement, ns, "solid displacement");
  s["velocity"] = nodal(f.solid_velocity, ns, "solid velocity");
  s["force"] = nodal(f.solid_force, ns, "solid force");
  s["traction_force_mapped"] = nodal(f.traction_mapped, ns, "mapped traction force");
  s["velocity_integral_mapped"] = nodal(f.velocity_integral_mapped, ns, "mapped velocity integral");
  auto& q = fluid_grid_.point_data;
  q["displacement"] = nodal(f.fluid_displacement, nf, "fluid displacement");
  q["velocity"] = nodal(f.fluid_velocity, nf, "fluid velocity");
  q["traction_force"] = nodal(f.traction_force, nf, "traction force");
  q["velocity_integral"] = nodal(f.velocity_integral, nf, "velocity integral");
  solid_series_.write(time, step, solid_grid_);
  fluid_series_.write(time, step, fluid_grid_);
}

}  // namespace fsi::coupling
