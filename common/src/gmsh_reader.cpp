// gmsh ASCII reader: MSH 2.2 and MSH 4.1, physical groups of dimension 1, 2 and 3 (tetrahedra).
//
// Every element that carries a physical tag goes into the group (dimension, tag); node
// indices are renumbered 0..n-1 in the order the nodes appear in the file. Errors name the
// file and the line ("mesh.msh:12: expected ..."), so a wrong path or a .geo passed by
// mistake is obvious.
#include "fsi/common/gmsh_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace fsi {
namespace {

// Nodes per element for the gmsh types we accept (0 = unsupported).
int nodes_per_element(int type) {
  switch (type) {
    case 1:
      return 2;  // line2
    case 2:
      return 3;  // tri3
    case 3:
      return 4;  // quad4
    case 8:
      return 3;  // line3
    case 9:
      return 6;  // tri6
    case 10:
      return 9;  // quad9
    case 15:
      return 1;  // point
    case 16:
      return 8;  // quad8
    case 4:
      return 4;  // tet4
    case 11:
      return 10;  // tet10
    case 5:
      return 8;  // hex8
    default:
      return 0;
  }
}

int dimension_of(int type) {
  switch (type) {
    case 15:
      return 0;
    case 1:
    case 8:
      return 1;
    case 2:
    case 3:
    case 9:
    case 10:
    case 16:
      return 2;
    default:
      return 3;
  }
}

// A line reader that remembers the line number for error messages.
class LineReader {
 public:
  LineReader(std::istream& in, const std::filesystem::path& path) : path_(path), in_(in) {}
  bool next(std::string& line) {
    while (std::getline(in_, line)) {
      ++number_;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.find_first_not_of(" \t") != std::string::npos) return true;
    }
    return false;
  }
  std::string require(const char* what) {
    std::string line;
    if (!next(line)) fail(fmt::format("unexpected end of file, expected {}", what));
    return line;
  }
  [[noreturn]] void fail(const std::string& message) const {
    throw std::runtime_error(fmt::format("{}:{}: {}", path_.string(), number_, message));
  }
  int line_number() const { return number_; }

 private:
  std::filesystem::path path_;
  std::istream& in_;
  int number_ = 0;
};

template <class T>
std::vector<T> parse_numbers(LineReader& reader, const std::string& line, std::size_t at_least, const char* what) {
  std::istringstream in(line);
  std::vector<T> values;
  T v;
  while (in >> v) values.push_back(v);
  if (!in.eof() || values.size() < at_least)
    reader.fail(fmt::format("expected {} (at least {} numbers), got '{}'", what, at_least, line));
  return values;
}

// A number read as a double (entity and node records) that must be a whole number in the range
// of T (a tag, a count): casting 7.7e9 to int is undefined behaviour.
template <class T>
T whole(LineReader& reader, double x, const char* what) {
  if (!(x >= static_cast<double>(std::numeric_limits<T>::min()) &&
        x < static_cast<double>(std::numeric_limits<T>::max()) + 1.0) ||  // exact for int and long
      x != std::floor(x))
    reader.fail(fmt::format("{} must be an integer, got {}", what, x));
  return static_cast<T>(x);
}

// A count from a section header: >= 0. It is not trusted for reserving memory (a header
// claiming 10^12 nodes in a 100-byte file must fail at the end of the file, not in the allocator).
long checked_count(LineReader& reader, long n, const char* what) {
  if (n < 0) reader.fail(fmt::format("{} must be >= 0, got {}", what, n));
  return n;
}
constexpr long kReserveAtMost = 1 << 16;

struct RawElement {
  int type;
  std::vector<long> nodes;  // gmsh node tags
};

struct ReaderState {
  std::map<std::pair<int, int>, std::string> names;                  // (dim, tag) -> name
  std::vector<std::pair<long, Eigen::Vector3d>> nodes;               // gmsh tag, position
  std::map<std::pair<int, int>, std::vector<RawElement>> groups;     // (dim, physical) -> elements
  std::map<std::pair<int, int>, int> group_type;                     // first element type
  std::map<std::pair<int, int>, std::vector<int>> entity_physicals;  // 4.1: (dim, entity) -> physicals
};

void add_element(LineReader& reader, ReaderState& state, int dim, int physical, int type, std::vector<long> nodes) {
  if (dim < 1 || dim > 3 || physical == 0) return;
  auto key = std::make_pair(dim, physical);
  auto [it, inserted] = state.group_type.emplace(key, type);
  if (!inserted && it->second != type)
    reader.fail(
        fmt::format("physical group {} (dim {}) mixes element types {} and {}; "
                    "one type per group is supported",
                    physical, dim, it->second, type));
  state.groups[key].push_back({type, std::move(nodes)});
}

void read_physical_names(LineReader& reader, ReaderState& state) {
  const auto count = parse_numbers<long>(reader, reader.require("number of physical names"), 1, "a count");
  for (long i = 0; i < count[0]; ++i) {
    const std::string line = reader.require("a physical name");
    std::istringstream in(line);
    int dim = 0, tag = 0;
    if (!(in >> dim >> tag)) reader.fail(fmt::format("expected 'dim tag \"name\"', got '{}'", line));
    const auto open = line.find('"');
    const auto close = line.rfind('"');
    if (open == std::string::npos || close == open) reader.fail("physical name without quotes: '" + line + "'");
    state.names[{dim, tag}] = line.substr(open + 1, close - open - 1);
  }
  if (reader.require("$EndPhysicalNames") != "$EndPhysicalNames") reader.fail("expected $EndPhysicalNames");
}

void read_nodes_v2(LineReader& reader, ReaderState& state) {
  const auto count = parse_numbers<long>(reader, reader.require("number of nodes"), 1, "a node count");
  const long n = checked_count(reader, count[0], "the node count");
  state.nodes.reserve(static_cast<std::size_t>(std::min(n, kReserveAtMost)));
  for (long i = 0; i < n; ++i) {
    const auto v = parse_numbers<double>(reader, reader.require("a node"), 4, "'id x y z'");
    state.nodes.push_back({whole<long>(reader, v[0], "a node id"), Eigen::Vector3d(v[1], v[2], v[3])});
  }
  if (reader.require("$EndNodes") != "$EndNodes") reader.fail("expected $EndNodes");
}

void read_elements_v2(LineReader& reader, ReaderState& state) {
  const auto count = parse_numbers<long>(reader, reader.require("number of elements"), 1, "an element count");
  for (long i = 0; i < count[0]; ++i) {
    const auto v = parse_numbers<long>(reader, reader.require("an element"), 3, "'id type ntags ...'");
    const int type = static_cast<int>(v[1]);
    if (v[2] < 0 || v[2] > static_cast<long>(v.size()))
      reader.fail(fmt::format("element {} has {} tags: must be between 0 and the numbers on its line", v[0], v[2]));
    const int ntags = static_cast<int>(v[2]);
    const int nn = nodes_per_element(type);
    if (dimension_of(type) > 2 && nn == 0) continue;  // other volume cells: not read
    if (nn == 0) reader.fail(fmt::format("unsupported gmsh element type {}", type));
    if (static_cast<int>(v.size()) != 3 + ntags + nn)
      reader.fail(fmt::format("element {} of type {} should have {} tags and {} nodes", v[0], type, ntags, nn));
    const int physical = ntags > 0 ? static_cast<int>(v[3]) : 0;
    add_element(reader, state, dimension_of(type), physical, type, std::vector<long>(v.begin() + 3 + ntags, v.end()));
  }
  if (reader.require("$EndElements") != "$EndElements") reader.fail("expected $EndElements");
}

void read_entities_v4(LineReader& reader, ReaderState& state) {
  const auto counts = parse_numbers<long>(reader, reader.require("entity counts"), 4, "four entity counts");
  for (int dim = 0; dim < 4; ++dim) {
    for (long i = 0; i < counts[static_cast<std::size_t>(dim)]; ++i) {
      const auto v = parse_numbers<double>(reader, reader.require("an entity"), dim == 0 ? 5 : 8, "an entity");
      // point: tag x y z nphys phys...; others: tag minxyz maxxyz nphys phys... nbound ...
      const std::size_t at = dim == 0 ? 4 : 7;
      const int tag = whole<int>(reader, v[0], "an entity tag");
      const int nphys = whole<int>(reader, v[at], "a physical tag count");
      if (nphys < 0 || v.size() < at + 1 + static_cast<std::size_t>(nphys)) reader.fail("truncated entity record");
      auto& phys = state.entity_physicals[{dim, tag}];
      for (int k = 0; k < nphys; ++k)
        phys.push_back(whole<int>(reader, v[at + 1 + static_cast<std::size_t>(k)], "a physical tag"));
    }
  }
  if (reader.require("$EndEntities") != "$EndEntities") reader.fail("expected $EndEntities");
}

void read_nodes_v4(LineReader& reader, ReaderState& state) {
  const auto header = parse_numbers<long>(reader, reader.require("node block header"), 4, "'blocks nodes min max'");
  state.nodes.reserve(
      static_cast<std::size_t>(std::min(checked_count(reader, header[1], "the node count"), kReserveAtMost)));
  for (long b = 0; b < header[0]; ++b) {
    const auto bh = parse_numbers<long>(reader, reader.require("an entity block"), 4, "'dim tag parametric n'");
    const long n = checked_count(reader, bh[3], "the block's node count");
    const bool parametric = bh[2] != 0;
    std::vector<long> tags;
    tags.reserve(static_cast<std::size_t>(std::min(n, kReserveAtMost)));
    for (long i = 0; i < n; ++i)
      tags.push_back(parse_numbers<long>(reader, reader.require("a node tag"), 1, "a node tag")[0]);
    for (long i = 0; i < n; ++i) {
      const auto x = parse_numbers<double>(reader, reader.require("node coordinates"), parametric ? 4 : 3, "'x y z'");
      state.nodes.push_back({tags[static_cast<std::size_t>(i)], Eigen::Vector3d(x[0], x[1], x[2])});
    }
  }
  if (reader.require("$EndNodes") != "$EndNodes") reader.fail("expected $EndNodes");
}

void read_elements_v4(LineReader& reader, ReaderState& state) {
  const auto header =
      parse_numbers<long>(reader, reader.require("element block header"), 4, "'blocks elements min max'");
  for (long b = 0; b < header[0]; ++b) {
    const auto bh = parse_numbers<long>(reader, reader.require("an element block"), 4, "'dim tag type n'");
    const int dim = static_cast<int>(bh[0]);
    const int entity = static_cast<int>(bh[1]);
    const int type = static_cast<int>(bh[2]);
    const int nn = nodes_per_element(type);
    if (nn == 0 && dim <= 2) reader.fail(fmt::format("unsupported gmsh element type {}", type));
    const auto phys_it = state.entity_physicals.find({dim, entity});
    for (long i = 0; i < bh[3]; ++i) {
      const auto v = parse_numbers<long>(reader, reader.require("an element"), 1, "an element");
      if (dim > 2 && nn == 0) continue;
      if (static_cast<int>(v.size()) != 1 + nn)
        reader.fail(fmt::format("element {} of type {} should have {} nodes", v[0], type, nn));
      if (phys_it == state.entity_physicals.end()) continue;
      for (int physical : phys_it->second)
        add_element(reader, state, dim, physical, type, std::vector<long>(v.begin() + 1, v.end()));
    }
  }
  if (reader.require("$EndElements") != "$EndElements") reader.fail("expected $EndElements");
}

void skip_section(LineReader& reader, const std::string& name) {
  const std::string end = "$End" + name.substr(1);
  std::string line;
  while (reader.next(line))
    if (line == end) return;
  reader.fail("section " + name + " has no " + end);
}

}  // namespace

const GmshGroup& GmshMesh::group(const std::string& name) const {
  for (const auto& g : groups)
    if (g.name == name) return g;
  std::string known;
  for (const auto& g : groups) known += (known.empty() ? "" : ", ") + g.name;
  throw std::runtime_error(fmt::format("mesh '{}' has no physical group '{}' (groups: {})", source.string(), name,
                                       known.empty() ? "none" : known));
}

bool GmshMesh::has_volume() const {
  for (const auto& g : groups)
    if (g.dimension == 3) return true;
  return false;
}

bool GmshMesh::has_group(const std::string& name) const {
  for (const auto& g : groups)
    if (g.name == name) return true;
  return false;
}

GmshMesh read_gmsh(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("cannot open mesh file '{}'", path.string()));
  return read_gmsh(in, path);
}

GmshMesh read_gmsh(std::istream& in, const std::filesystem::path& path) {
  LineReader reader(in, path);
  ReaderState state;
  std::string line;
  if (!reader.next(line) || line != "$MeshFormat")
    reader.fail("not a gmsh mesh: expected '$MeshFormat' on the first line" +
                (line.empty() ? std::string() : ", got '" + line.substr(0, 60) + "'"));
  const std::string version_line = reader.require("the format line");
  std::istringstream vin(version_line);
  double version = 0;
  int binary = 0;
  if (!(vin >> version >> binary)) reader.fail("bad format line '" + version_line + "'");
  if (binary != 0) reader.fail("binary MSH files are not supported; mesh with '-format msh22' (ASCII)");
  const bool v4 = version >= 4.0;
  if (!(version >= 2.0 && version < 3.0) && !(version >= 4.1 && version < 5.0))
    reader.fail(fmt::format("MSH version {} is not supported (2.2 or 4.1 ASCII)", version));
  if (reader.require("$EndMeshFormat") != "$EndMeshFormat") reader.fail("expected $EndMeshFormat");

  bool have_nodes = false, have_elements = false;
  while (reader.next(line)) {
    if (line == "$PhysicalNames") {
      read_physical_names(reader, state);
    } else if (line == "$Entities" && v4) {
      read_entities_v4(reader, state);
    } else if (line == "$Nodes") {
      v4 ? read_nodes_v4(reader, state) : read_nodes_v2(reader, state);
      have_nodes = true;
    } else if (line == "$Elements") {
      if (!have_nodes) reader.fail("$Elements before $Nodes");
      v4 ? read_elements_v4(reader, state) : read_elements_v2(reader, state);
      have_elements = true;
    } else if (!line.empty() && line[0] == '$') {
      skip_section(reader, line);
    } else {
      reader.fail("expected a section header ($Name), got '" + line.substr(0, 60) + "'");
    }
  }
  if (!have_nodes || !have_elements) reader.fail("mesh has no $Nodes or no $Elements section");

  GmshMesh mesh;
  mesh.source = path;
  mesh.nodes.resize(static_cast<Eigen::Index>(state.nodes.size()), 2);
  mesh.z.resize(static_cast<Eigen::Index>(state.nodes.size()));
  std::unordered_map<long, int> index;
  index.reserve(state.nodes.size());
  for (std::size_t i = 0; i < state.nodes.size(); ++i) {
    mesh.nodes.row(static_cast<Eigen::Index>(i)) = state.nodes[i].second.head<2>().transpose();
    mesh.z(static_cast<Eigen::Index>(i)) = state.nodes[i].second.z();
    index[state.nodes[i].first] = static_cast<int>(i);
  }
  for (const auto& [key, elements] : state.groups) {
    GmshGroup group;
    group.dimension = key.first;
    group.physical_tag = key.second;
    const auto name_it = state.names.find(key);
    group.name = name_it != state.names.end() ? name_it->second : fmt::format("tag{}", key.second);
    group.element_type = state.group_type.at(key);
    const int nn = nodes_per_element(group.element_type);
    group.elements.resize(static_cast<Eigen::Index>(elements.size()), nn);
    for (std::size_t e = 0; e < elements.size(); ++e)
      for (int k = 0; k < nn; ++k) {
        const auto it = index.find(elements[e].nodes[static_cast<std::size_t>(k)]);
        if (it == index.end())
          throw std::runtime_error(fmt::format("{}: element of group '{}' uses node {} that is not in $Nodes",
                                               path.string(), group.name,
                                               elements[e].nodes[static_cast<std::size_t>(k)]));
        group.elements(static_cast<Eigen::Index>(e), k) = it->second;
      }
    mesh.groups.push_back(std::move(group));
  }
  return mesh;
}

}  // namespace fsi
