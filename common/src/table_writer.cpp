#include "fsi/common/table_writer.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace fsi {

CsvWriter::CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns)
    : out_(path), columns_(columns.size()), path_(path) {
  if (!out_) throw std::runtime_error("cannot write '" + path.string() + "'");
  row(columns);
}

void CsvWriter::row(const std::vector<std::string>& values) {
  if (values.size() != columns_)
    throw std::invalid_argument(fmt::format("{}: row has {} values, header has {}",
                                            path_.string(), values.size(), columns_));
  for (std::size_t i = 0; i < values.size(); ++i) out_ << (i ? "," : "") << values[i];
  out_ << '\n';
  out_.flush();
}

void CsvWriter::row(const std::vector<double>& values) {
  std::vector<std::string> text;
  text.reserve(values.size());
  for (double v : values) text.push_back(fmt::format("{:.17g}", v));
  row(text);
}

}  // namespace fsi
