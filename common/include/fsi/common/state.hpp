#pragma once
// A solver's state as named, typed entries, restored bit for bit: what a checkpoint holds.
// The physics side fills one in save_state() and reads it back in load_state(); the
// protocol carries the serialised bytes opaquely and the coupler writes them to disk.
//
//   StateArchive s;
//   s.put("velocity", u);  s.put("step", std::int64_t{12});
//   const std::string bytes = s.serialize();
//   const StateArchive back = StateArchive::parse(bytes, "fluid checkpoint of step 12");
//   Eigen::VectorXd u2 = back.vector("velocity", u.size());   // throws naming the entry
//
// Format (little-endian): "FSISTATE", u32 format version, u32 entry count, then per entry
// u32 name length, name, u8 type (1 vector of f64, 2 f64, 3 i64, 4 text), u64 byte length,
// bytes. Doubles are stored as their bit patterns, so a round trip is exact.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace fsi {

// A state that does not parse, lacks an entry or has one of the wrong size or type.
class StateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class StateArchive {
 public:
  static constexpr std::uint32_t kFormatVersion = 1;

  void put(const std::string& name, const Eigen::VectorXd& values);
  void put(const std::string& name, const std::vector<double>& values);
  void put(const std::string& name, double value);
  void put(const std::string& name, std::int64_t value);
  void put(const std::string& name, const std::string& text);
  // Matrices are stored column-major with their shape ("name", "name.rows").
  void put_matrix(const std::string& name, const Eigen::MatrixXd& m);

  bool has(const std::string& name) const { return entries_.count(name) > 0; }
  // `expected_size` < 0: any size.
  Eigen::VectorXd vector(const std::string& name, Eigen::Index expected_size = -1) const;
  double real(const std::string& name) const;
  std::int64_t integer(const std::string& name) const;
  std::string text(const std::string& name) const;
  Eigen::MatrixXd matrix(const std::string& name) const;
  std::vector<std::string> names() const;

  std::string serialize() const;
  // `where` names the state in errors ("fluid checkpoint of step 50").
  static StateArchive parse(const std::string& bytes, const std::string& where);

 private:
  enum class Type : std::uint8_t { Vector = 1, Real = 2, Integer = 3, Text = 4 };
  struct Entry {
    Type type;
    std::string bytes;
  };
  const Entry& entry(const std::string& name, Type type) const;
  std::map<std::string, Entry> entries_;
  std::string where_ = "state";
};

// CRC-32 (zlib) of a byte string, as 8 hex digits: the checksum in checkpoint manifests.
std::string crc32_hex(const std::string& bytes);

}  // namespace fsi
