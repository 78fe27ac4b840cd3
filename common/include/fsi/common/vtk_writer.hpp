#pragma once
// VTK XML unstructured grids (.vtu) and a ParaView collection (.pvd) that grows one entry
// per written step (rewritten each time so it is valid after a crash). Arrays with 2 columns
// are written as 3-vectors (z = 0); 9 columns are a 3x3 tensor (row-major), which ParaView
// shows as a tensor. Two encodings (scene key time.vtk_format):
//  - Binary (default): what ParaView writes by default, every array zlib-compressed in
//    blocks of 32 KiB in one raw AppendedData section (header_type UInt64,
//    compressor vtkZLibDataCompressor); doubles exactly as in memory.
//  - Ascii: readable text, values with 10 significant digits (points 12).
#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace fsi {

enum class VtkCellType : int {
  Vertex = 1,
  Line = 3,
  Triangle = 5,
  Quad = 9,
  Tetra = 10,
  Hexahedron = 12,
  QuadraticTriangle = 22,
  QuadraticQuad = 23,
  QuadraticTetra = 24,
  BiquadraticQuad = 28
};

struct VtkGrid {
  Eigen::MatrixXd points;                             // n x 2 or n x 3
  std::vector<std::vector<int>> cells;                // node indices per cell
  std::vector<VtkCellType> cell_types;                // one per cell
  std::map<std::string, Eigen::MatrixXd> point_data;  // n x ncomp (2 comps padded to 3)
  std::map<std::string, Eigen::MatrixXd> cell_data;   // ncells x ncomp
};

enum class VtkFormat { Binary, Ascii };
// "binary" or "ascii"; anything else throws std::invalid_argument.
VtkFormat parse_vtk_format(const std::string& name);
const char* to_string(VtkFormat format);

void write_vtu(const std::filesystem::path& path, const VtkGrid& grid, VtkFormat format = VtkFormat::Binary);

// The in-plane Cauchy stress (xx, yy, xy) per row as a 3x3 tensor per row (zz = 0).
Eigen::MatrixXd plane_stress_tensor(const Eigen::MatrixX3d& xx_yy_xy);
// Von Mises equivalent of the in-plane stress (plane stress formula).
Eigen::VectorXd von_mises(const Eigen::MatrixX3d& xx_yy_xy);

class PvdSeries {
 public:
  PvdSeries() = default;
  // Files go to dir/<name>_<step>.vtu, the collection to dir/<name>.pvd. An existing
  // collection (a resumed run) is continued: writing step k drops its entries of steps >= k.
  PvdSeries(std::filesystem::path dir, std::string name, VtkFormat format = VtkFormat::Binary);
  std::filesystem::path write(double time, int step, const VtkGrid& grid);

 private:
  std::filesystem::path dir_;
  std::string name_;
  VtkFormat format_ = VtkFormat::Binary;
  struct Entry {
    double time;
    int step;
    std::string file;
  };
  std::vector<Entry> entries_;
};

}  // namespace fsi
