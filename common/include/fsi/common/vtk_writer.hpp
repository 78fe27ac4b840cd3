#pragma once
// ASCII VTK XML unstructured grids (.vtu) and a ParaView collection (.pvd) that grows one
// entry per written step (rewritten each time so it is valid after a crash).
#include <Eigen/Core>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace fsi {

enum class VtkCellType : int { Line = 3, Triangle = 5, Quad = 9 };

struct VtkGrid {
  Eigen::MatrixXd points;                    // n x 2 or n x 3
  std::vector<std::vector<int>> cells;       // node indices per cell
  std::vector<VtkCellType> cell_types;       // one per cell
  std::map<std::string, Eigen::MatrixXd> point_data;  // n x ncomp (2 comps padded to 3)
  std::map<std::string, Eigen::MatrixXd> cell_data;   // ncells x ncomp
};

void write_vtu(const std::filesystem::path& path, const VtkGrid& grid);

class PvdSeries {
 public:
  PvdSeries() = default;
  // Files go to dir/<name>_<step>.vtu, the collection to dir/<name>.pvd.
  PvdSeries(std::filesystem::path dir, std::string name);
  std::filesystem::path write(double time, int step, const VtkGrid& grid);

 private:
  std::filesystem::path dir_;
  std::string name_;
  std::vector<std::pair<double, std::string>> entries_;
};

}  // namespace fsi
