// libFuzzer target: bytes -> fsi::read_gmsh (the stream overload; the same code as
// read_gmsh(path) after opening the file), then every group is looked up and checked.
//
// Oracle: std::runtime_error (the documented error of gmsh_reader.hpp) is fine. Any other
// exception type, a crash, UB, a hang, or a mesh whose element indices are not valid node
// rows is a finding. Inputs above 64 KiB are skipped (the reader is line based; big inputs
// only slow the fuzzer down).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <sstream>
#include <string>
#include <typeinfo>

#include "fsi/common/gmsh_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 65536) return 0;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const fsi::GmshMesh mesh = fsi::read_gmsh(in, "fuzz.msh");
    for (const auto& g : mesh.groups) {
      (void)mesh.group(g.name);
      if (!mesh.has_group(g.name)) std::abort();
      for (Eigen::Index e = 0; e < g.elements.rows(); ++e)
        for (Eigen::Index k = 0; k < g.elements.cols(); ++k)
          if (g.elements(e, k) < 0 || g.elements(e, k) >= mesh.nodes.rows()) {
            std::fprintf(stderr, "fuzz_gmsh: group '%s' element %ld uses node row %d of %ld\n", g.name.c_str(),
                         static_cast<long>(e), g.elements(e, k), static_cast<long>(mesh.nodes.rows()));
            std::abort();
          }
    }
    try {
      (void)mesh.group("no such group \x01");
      std::abort();
    } catch (const std::runtime_error&) {
    }
  } catch (const std::runtime_error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_gmsh: a non-runtime_error exception escaped: %s: %s\n", typeid(e).name(), e.what());
    std::abort();
  }
  return 0;
}
