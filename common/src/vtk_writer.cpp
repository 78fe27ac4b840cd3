#include "fsi/common/vtk_writer.hpp"

#include <fmt/format.h>

#include <fstream>
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

PvdSeries::PvdSeries(std::filesystem::path dir, std::string name)
    : dir_(std::move(dir)), name_(std::move(name)) {
  std::filesystem::create_directories(dir_);
}

std::filesystem::path PvdSeries::write(double time, int step, const VtkGrid& grid) {
  const std::string file = fmt::format("{}_{:06d}.vtu", name_, step);
  write_vtu(dir_ / file, grid);
  entries_.emplace_back(time, file);
  std::ofstream pvd(dir_ / (name_ + ".pvd"));
  pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const auto& [t, f] : entries_)
    pvd << fmt::format("<DataSet timestep=\"{:.10g}\" part=\"0\" file=\"{}\"/>\n", t, f);
  pvd << "</Collection>\n</VTKFile>\n";
  return dir_ / file;
}

}  // namespace fsi
