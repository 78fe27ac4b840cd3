#include "fsi/common/vtk_writer.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <regex>
#include <stdexcept>
#include <system_error>

#include "fsi/common/write_check.hpp"

namespace fsi {
namespace {

// ---- ASCII ----------------------------------------------------------------------------

void write_array(std::ofstream& out, const std::string& name, const Eigen::MatrixXd& data) {
  const bool vector2 = data.cols() == 2;
  const int comps = vector2 ? 3 : static_cast<int>(data.cols());
  out << fmt::format("<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n", name,
                     comps);
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    for (Eigen::Index j = 0; j < data.cols(); ++j) out << fmt::format("{:.10g} ", data(i, j));
    if (vector2) out << "0 ";
    out << '\n';
  }
  out << "</DataArray>\n";
}

void write_ascii(std::ofstream& out, const VtkGrid& grid) {
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

// ---- binary, appended, zlib-compressed (what ParaView writes by default) --------------

static_assert(sizeof(double) == 8 && sizeof(std::uint64_t) == 8);

bool little_endian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

template <class T>
void put(std::string& bytes, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  bytes.append(raw, sizeof(T));
}

// VTK's compressed layout with header_type UInt64: [number of blocks, uncompressed block
// size, uncompressed size of the last block if partial (else 0), compressed size of each
// block], then the compressed blocks. VTK writes blocks of 32 KiB.
constexpr std::size_t kBlock = 32768;

std::string compressed(const std::string& raw) {
  const std::size_t n = raw.size();
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::string header, body;
  put<std::uint64_t>(header, blocks);
  put<std::uint64_t>(header, kBlock);
  put<std::uint64_t>(header, n % kBlock);
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t len = std::min(kBlock, n - b * kBlock);
    uLongf out_len = compressBound(static_cast<uLong>(len));
    std::string out(out_len, '\0');
    if (compress2(reinterpret_cast<Bytef*>(out.data()), &out_len,
                  reinterpret_cast<const Bytef*>(raw.data() + b * kBlock), static_cast<uLong>(len),
                  Z_DEFAULT_COMPRESSION) != Z_OK)
      throw std::runtime_error("VTK output: zlib compression failed");
    put<std::uint64_t>(header, out_len);
    body.append(out.data(), out_len);
  }
  return header + body;
}

struct Appended {
  std::string xml;   // the DataArray elements, in order
  std::string data;  // their compressed bytes, in the same order
  void add(const std::string& type, const std::string& name, int components, const std::string& raw) {
    xml += fmt::format("<DataArray type=\"{}\"{} NumberOfComponents=\"{}\" format=\"appended\" offset=\"{}\"/>\n", type,
                       name.empty() ? "" : fmt::format(" Name=\"{}\"", name), components, data.size());
    data += compressed(raw);
  }
  // Rows of doubles; 2 columns are written as 3 (z = 0).
  void add_doubles(const std::string& name, const Eigen::MatrixXd& m) {
    const bool vector2 = m.cols() == 2;
    const int comps = vector2 ? 3 : static_cast<int>(m.cols());
    std::string raw;
    raw.reserve(static_cast<std::size_t>(m.rows()) * comps * 8);
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      for (Eigen::Index j = 0; j < m.cols(); ++j) put<double>(raw, m(i, j));
      if (vector2) put<double>(raw, 0.0);
    }
    add("Float64", name, comps, raw);
  }
};

void write_binary(std::ofstream& out, const VtkGrid& grid) {
  if (!little_endian()) throw std::runtime_error("binary VTK output needs a little-endian machine; use ascii");
  Appended a;
  std::string points_xml, cells_xml, point_xml, cell_xml;
  {
    Eigen::MatrixXd p = Eigen::MatrixXd::Zero(grid.points.rows(), 3);
    p.leftCols(std::min<Eigen::Index>(3, grid.points.cols())) =
        grid.points.leftCols(std::min<Eigen::Index>(3, grid.points.cols()));
    a.add_doubles("Points", p);
    points_xml = a.xml;
    a.xml.clear();
  }
  {
    std::string conn, offsets, types;
    std::int64_t offset = 0;
    for (const auto& cell : grid.cells) {
      for (int n : cell) put<std::int64_t>(conn, n);
      put<std::int64_t>(offsets, offset += static_cast<std::int64_t>(cell.size()));
    }
    for (auto t : grid.cell_types) put<std::uint8_t>(types, static_cast<std::uint8_t>(t));
    a.add("Int64", "connectivity", 1, conn);
    a.add("Int64", "offsets", 1, offsets);
    a.add("UInt8", "types", 1, types);
    cells_xml = a.xml;
    a.xml.clear();
  }
  for (const auto& [name, data] : grid.point_data) a.add_doubles(name, data);
  point_xml = a.xml;
  a.xml.clear();
  for (const auto& [name, data] : grid.cell_data) a.add_doubles(name, data);
  cell_xml = a.xml;
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n"
      << "<UnstructuredGrid>\n"
      << fmt::format("<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", grid.points.rows(), grid.cells.size())
      << "<Points>\n"
      << points_xml << "</Points>\n<Cells>\n"
      << cells_xml << "</Cells>\n<PointData>\n"
      << point_xml << "</PointData>\n<CellData>\n"
      << cell_xml << "</CellData>\n</Piece>\n</UnstructuredGrid>\n"
      << "<AppendedData encoding=\"raw\">\n_";
  out.write(a.data.data(), static_cast<std::streamsize>(a.data.size()));
  out << "\n</AppendedData>\n</VTKFile>\n";
}

}  // namespace

VtkFormat parse_vtk_format(const std::string& name) {
  if (name == "binary") return VtkFormat::Binary;
  if (name == "ascii") return VtkFormat::Ascii;
  throw std::invalid_argument("VTK format '" + name + "' is not binary or ascii");
}

const char* to_string(VtkFormat format) { return format == VtkFormat::Ascii ? "ascii" : "binary"; }

void write_vtu(const std::filesystem::path& path, const VtkGrid& grid, VtkFormat format) {
  if (grid.cells.size() != grid.cell_types.size())
    throw std::invalid_argument("write_vtu: cells and cell_types differ in size");
  std::ofstream out(path, std::ios::binary);
  if (!out) throw WriteError(path, errno ? errno : EIO);
  errno = 0;
  try {
    if (format == VtkFormat::Ascii)
      write_ascii(out, grid);
    else
      write_binary(out, grid);
    check_written(out, path);
  } catch (const WriteError&) {
    out.close();
    std::error_code ignored;
    std::filesystem::remove(path, ignored);  // no half file beside the series
    throw;
  }
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

PvdSeries::PvdSeries(std::filesystem::path dir, std::string name, VtkFormat format)
    : dir_(std::move(dir)), name_(std::move(name)), format_(format) {
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
  write_vtu(dir_ / file, grid, format_);
  std::erase_if(entries_, [&](const Entry& e) { return e.step >= step; });
  entries_.push_back({time, step, file});
  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const auto& e : entries_)
    pvd += fmt::format("<DataSet timestep=\"{:.10g}\" part=\"0\" file=\"{}\"/>\n", e.time, e.file);
  pvd += "</Collection>\n</VTKFile>\n";
  write_file_atomic(dir_ / (name_ + ".pvd"), pvd);
  return dir_ / file;
}

}  // namespace fsi
