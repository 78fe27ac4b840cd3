#include "fsi/common/vtk_writer.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <stdexcept>

namespace fsi {
namespace {

void write_array(std::ofstream& out, const std::string& name, const Eigen::MatrixXd& data) {
  const bool vector2 = data.cols() == 2;
  const int comps = vector2 ? 3 : static_cast<int>(data.cols());
  out << fmt::format("<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n",
                     name, comps);
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    for (Eigen::Index j = 0; j < data.cols(); ++j) out << fmt::format("{:.10g} ", data(i, j));
    if (vector2) out << "0 ";
    out << '\n';
  }
  out << "</DataArray>\n";
}

}  // namespace

void write_vtu(const std::filesystem::path& path, const VtkGrid& grid) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path.string() + "'");
  if (grid.cells.size() != grid.cell_types.size())
    throw std::invalid_argument("write_vtu: cells and cell_types differ in size");
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<UnstructuredGrid>\n"
      << fmt::format("<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", grid.points.rows(), grid.cells.size())
      << "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (Eigen::Index i = 0; i < grid.points.rows(); ++i)
    out << fmt::format("{:.12g} {:.12g} {:.12g}\n", grid.points(i, 0), grid.points(i, 1),
                       grid.points.cols() > 2 ? grid.points(i, 2) : 0.0);
  out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& cell : grid.cells) {
    for (int n : cell) out << n << ' ';
    out << '\n';
  }
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  long offset = 0;
  for (const auto& cell : grid.cells) out << (offset += static_cast<long>(cell.size())) << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (auto t : grid.cell_types) out << static_cast<int>(t) << '\n';
  out << "</DataArray>\n</Cells>\n<PointData>\n";
  for (const auto& [name, data] : grid.point_data) write_array(out, name, data);
  out << "</PointData>\n<CellData>\n";
  for (const auto& [name, data] : grid.cell_data) write_array(out, name, data);
  out << "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

Eigen::MatrixXd plane_stress_tensor(const Eigen::MatrixX3d& s) {
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(s.rows(), 9);
  t.col(0) = s.col(0);  // xx
  t.col(1) = s.col(2);  // xy
  t.col(3) = s.col(2);  // yx
  t.col(4) = s.col(1);  // yy
  return t;
}

Eigen::VectorXd von_mises(const Eigen::MatrixX3d& s) {
  Eigen::VectorXd v(s.rows());
  for (Eigen::Index i = 0; i < s.rows(); ++i)
    v[i] = std::sqrt(s(i, 0) * s(i, 0) - s(i, 0) * s(i, 1) + s(i, 1) * s(i, 1) + 3 * s(i, 2) * s(i, 2));
  return v;
}

PvdSeries::PvdSeries(std::filesystem::path dir, std::string name)
    : dir_(std::move(dir)), name_(std::move(name)) {
  std::filesystem::create_directories(dir_);
  // Continue the collection of an earlier segment of this run (resume).
  std::ifstream in(dir_ / (name_ + ".pvd"));
  const std::regex entry("<DataSet timestep=\"([^\"]+)\" part=\"0\" file=\"(" + name_ + "_([0-9]+)\\.vtu)\"/>");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, entry)) entries_.push_back({std::stod(m[1]), std::stoi(m[3]), m[2]});
  }
}

std::filesystem::path PvdSeries::write(double time, int step, const VtkGrid& grid) {
  const std::string file = fmt::format("{}_{:06d}.vtu", name_, step);
  write_vtu(dir_ / file, grid);
  std::erase_if(entries_, [&](const Entry& e) { return e.step >= step; });
  entries_.push_back({time, step, file});
  const auto path = dir_ / (name_ + ".pvd");
  {
    std::ofstream pvd(path.string() + ".tmp");
    pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
    for (const auto& e : entries_)
      pvd << fmt::format("<DataSet timestep=\"{:.10g}\" part=\"0\" file=\"{}\"/>\n", e.time, e.file);
    pvd << "</Collection>\n</VTKFile>\n";
  }
  std::filesystem::rename(path.string() + ".tmp", path);
  return dir_ / file;
}

}  // namespace fsi
