// gmsh reader: a real mesh in both ASCII formats, and files that are not meshes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include "fsi/common/gmsh_reader.hpp"

namespace {

std::filesystem::path temp_file(const std::string& name, const std::string& text) {
  auto path = std::filesystem::temp_directory_path() / ("fsi_fluid_test_" + name);
  std::ofstream(path) << text;
  return path;
}

constexpr const char* kSquare22 = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
1 1 "bottom"
2 2 "fluid"
$EndPhysicalNames
$Nodes
4
10 0 0 0
20 1 0 0
30 1 1 0
40 0 1 0
$EndNodes
$Elements
4
1 15 2 0 1 10
2 1 2 1 1 10 20
3 2 2 2 1 10 20 30
4 2 2 2 1 10 30 40
$EndElements
)";

TEST(GmshReader, ReadsMsh22WithRenumberedNodesAndNamedGroups) {
  const auto mesh = fsi::read_gmsh(temp_file("square22.msh", kSquare22));
  ASSERT_EQ(mesh.nodes.rows(), 4);
  EXPECT_DOUBLE_EQ(mesh.nodes(2, 0), 1.0);
  const auto& fluid = mesh.group("fluid");
  EXPECT_EQ(fluid.dimension, 2);
  EXPECT_EQ(fluid.element_type, 2);
  ASSERT_EQ(fluid.elements.rows(), 2);
  EXPECT_EQ(fluid.elements(1, 2), 3);  // node tag 40 -> index 3
  const auto& bottom = mesh.group("bottom");
  EXPECT_EQ(bottom.dimension, 1);
  EXPECT_EQ(bottom.elements(0, 1), 1);
  EXPECT_FALSE(mesh.has_group("top"));
  try {
    (void)mesh.group("top");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bottom"), std::string::npos) << e.what();
  }
}

TEST(GmshReader, ReadsGmshGeneratedMeshInBothFormats) {
  const std::filesystem::path geo = FSI_FLUID_SOURCE_DIR "/configs/meshes/dfg_cylinder.geo";
  const auto dir = std::filesystem::temp_directory_path();
  for (const std::string format : {"msh22", "msh41"}) {
    const auto out = dir / ("fsi_fluid_test_dfg_" + format + ".msh");
    const std::string cmd = "gmsh -2 -v 0 -format " + format + " -setnumber h 0.08 '" + geo.string() + "' -o '" +
                            out.string() + "' > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const auto mesh = fsi::read_gmsh(out);
    for (const char* name : {"inlet", "outlet", "walls", "cylinder", "fluid"})
      EXPECT_TRUE(mesh.has_group(name)) << name;
    EXPECT_GT(mesh.group("fluid").elements.rows(), 100);
    // Cylinder nodes lie on the circle.
    const auto& cyl = mesh.group("cylinder");
    for (Eigen::Index e = 0; e < cyl.elements.rows(); ++e) {
      const Eigen::Vector2d x = mesh.nodes.row(cyl.elements(e, 0)).transpose();
      EXPECT_NEAR((x - Eigen::Vector2d(0.2, 0.2)).norm(), 0.05, 1e-9);
    }
  }
}

TEST(GmshReader, FileThatIsNotAMeshNamesFileAndLine) {
  const auto path = temp_file("not_a_mesh.msh", "// a geo file\nPoint(1) = {0, 0, 0};\n");
  try {
    (void)fsi::read_gmsh(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string() + ":1:"), std::string::npos) << what;
    EXPECT_NE(what.find("not a gmsh mesh"), std::string::npos) << what;
  }
}

TEST(GmshReader, TruncatedNodeSectionNamesTheLine) {
  const auto path = temp_file("truncated.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 x 0 0\n");
  try {
    (void)fsi::read_gmsh(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(":7:"), std::string::npos) << e.what();
  }
}

TEST(GmshReader, MissingFileIsAnError) {
  EXPECT_THROW((void)fsi::read_gmsh("/nonexistent/mesh.msh"), std::runtime_error);
}

}  // namespace
