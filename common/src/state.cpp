#include "fsi/common/state.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <cstring>

namespace fsi {
namespace {

constexpr char kMagic[8] = {'F', 'S', 'I', 'S', 'T', 'A', 'T', 'E'};

template <class T>
void append(std::string& out, T value) {
  char buf[sizeof(T)];
  std::memcpy(buf, &value, sizeof(T));
  out.append(buf, sizeof(T));
}

class Reader {
 public:
  Reader(const std::string& bytes, const std::string& where) : bytes_(bytes), where_(where) {}
  template <class T>
  T read(const char* what) {
    T value;
    std::memcpy(&value, take(sizeof(T), what), sizeof(T));
    return value;
  }
  std::string read_bytes(std::size_t n, const char* what) { return std::string(take(n, what), n); }
  bool done() const { return pos_ == bytes_.size(); }
  std::size_t position() const { return pos_; }

 private:
  const char* take(std::size_t n, const char* what) {
    if (n > bytes_.size() - pos_)
      throw StateError(fmt::format("{}: truncated at byte {} of {} (reading {})", where_, pos_, bytes_.size(), what));
    const char* p = bytes_.data() + pos_;
    pos_ += n;
    return p;
  }
  const std::string& bytes_;
  const std::string& where_;
  std::size_t pos_ = 0;
};

const char* type_name(std::uint8_t t) {
  switch (t) {
    case 1:
      return "vector";
    case 2:
      return "real";
    case 3:
      return "integer";
    case 4:
      return "text";
    default:
      return "unknown";
  }
}

}  // namespace

void StateArchive::put(const std::string& name, const Eigen::VectorXd& values) {
  std::string bytes(static_cast<std::size_t>(values.size()) * sizeof(double), '\0');
  if (values.size() > 0) std::memcpy(bytes.data(), values.data(), bytes.size());
  entries_[name] = Entry{Type::Vector, std::move(bytes)};
}

void StateArchive::put(const std::string& name, const std::vector<double>& values) {
  put(name,
      Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()))));
}

void StateArchive::put(const std::string& name, double value) {
  std::string bytes;
  append(bytes, value);
  entries_[name] = Entry{Type::Real, std::move(bytes)};
}

void StateArchive::put(const std::string& name, std::int64_t value) {
  std::string bytes;
  append(bytes, value);
  entries_[name] = Entry{Type::Integer, std::move(bytes)};
}

void StateArchive::put(const std::string& name, const std::string& text) { entries_[name] = Entry{Type::Text, text}; }

void StateArchive::put_matrix(const std::string& name, const Eigen::MatrixXd& m) {
  put(name, Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(m.data(), m.size())));
  put(name + ".rows", static_cast<std::int64_t>(m.rows()));
}

const StateArchive::Entry& StateArchive::entry(const std::string& name, Type type) const {
  const auto it = entries_.find(name);
  if (it == entries_.end()) throw StateError(fmt::format("{}: no entry '{}'", where_, name));
  if (it->second.type != type)
    throw StateError(fmt::format("{}: entry '{}' is a {}, expected a {}", where_, name,
                                 type_name(static_cast<std::uint8_t>(it->second.type)),
                                 type_name(static_cast<std::uint8_t>(type))));
  return it->second;
}

Eigen::VectorXd StateArchive::vector(const std::string& name, Eigen::Index expected_size) const {
  const Entry& e = entry(name, Type::Vector);
  const auto n = static_cast<Eigen::Index>(e.bytes.size() / sizeof(double));
  if (expected_size >= 0 && n != expected_size)
    throw StateError(
        fmt::format("{}: entry '{}' has {} values, this configuration needs {} (a different mesh or "
                    "scene?)",
                    where_, name, n, expected_size));
  Eigen::VectorXd v(n);
  if (n > 0) std::memcpy(v.data(), e.bytes.data(), e.bytes.size());
  return v;
}

double StateArchive::real(const std::string& name) const {
  double v;
  std::memcpy(&v, entry(name, Type::Real).bytes.data(), sizeof v);
  return v;
}

std::int64_t StateArchive::integer(const std::string& name) const {
  std::int64_t v;
  std::memcpy(&v, entry(name, Type::Integer).bytes.data(), sizeof v);
  return v;
}

std::string StateArchive::text(const std::string& name) const { return entry(name, Type::Text).bytes; }

Eigen::MatrixXd StateArchive::matrix(const std::string& name) const {
  const Eigen::VectorXd v = vector(name);
  const auto rows = static_cast<Eigen::Index>(integer(name + ".rows"));
  if (rows < 0 || (rows == 0 && v.size() != 0) || (rows > 0 && v.size() % rows != 0))
    throw StateError(fmt::format("{}: matrix '{}' has {} values for {} rows", where_, name, v.size(), rows));
  return rows == 0 ? Eigen::MatrixXd()
                   : Eigen::MatrixXd(Eigen::Map<const Eigen::MatrixXd>(v.data(), rows, v.size() / rows));
}

std::vector<std::string> StateArchive::names() const {
  std::vector<std::string> out;
  for (const auto& [name, e] : entries_) out.push_back(name);
  return out;
}

std::string StateArchive::serialize() const {
  std::string out(kMagic, sizeof kMagic);
  append(out, kFormatVersion);
  append(out, static_cast<std::uint32_t>(entries_.size()));
  for (const auto& [name, e] : entries_) {
    append(out, static_cast<std::uint32_t>(name.size()));
    out += name;
    append(out, static_cast<std::uint8_t>(e.type));
    append(out, static_cast<std::uint64_t>(e.bytes.size()));
    out += e.bytes;
  }
  return out;
}

StateArchive StateArchive::parse(const std::string& bytes, const std::string& where) {
  if (bytes.compare(0, sizeof kMagic, std::string(kMagic, sizeof kMagic)) != 0)
    throw StateError(fmt::format("{}: not a solver state (no FSISTATE header; {} bytes)", where, bytes.size()));
  Reader in(bytes, where);
  in.read_bytes(sizeof kMagic, "the header");
  const auto version = in.read<std::uint32_t>("the format version");
  if (version != kFormatVersion)
    throw StateError(
        fmt::format("{}: state format version {}, this build reads version {}", where, version, kFormatVersion));
  const auto count = in.read<std::uint32_t>("the entry count");
  StateArchive s;
  s.where_ = where;
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto name_size = in.read<std::uint32_t>("an entry name's length");
    const std::string name = in.read_bytes(name_size, "an entry name");
    const auto type = in.read<std::uint8_t>("an entry type");
    if (type < 1 || type > 4) throw StateError(fmt::format("{}: entry '{}' has unknown type {}", where, name, type));
    const auto size = in.read<std::uint64_t>("an entry size");
    if ((type == 2 || type == 3) && size != 8)
      throw StateError(fmt::format("{}: entry '{}' ({}) has {} bytes, expected 8", where, name, type_name(type), size));
    if (type == 1 && size % sizeof(double) != 0)
      throw StateError(
          fmt::format("{}: vector entry '{}' has {} bytes, not a whole number of doubles", where, name, size));
    s.entries_[name] = Entry{static_cast<Type>(type), in.read_bytes(static_cast<std::size_t>(size), "entry data")};
  }
  if (!in.done())
    throw StateError(fmt::format("{}: {} trailing bytes after {} entries", where, bytes.size() - in.position(), count));
  return s;
}

std::string crc32_hex(const std::string& bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  std::size_t pos = 0;
  while (pos < bytes.size()) {
    const auto chunk = static_cast<uInt>(std::min<std::size_t>(bytes.size() - pos, 1u << 30));
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + pos), chunk);
    pos += chunk;
  }
  return fmt::format("{:08x}", static_cast<unsigned long>(crc));
}

}  // namespace fsi
