// DFG 2D-1 (Schafer & Turek 1996, Re 20) through the scene files and NavierStokesFluid:
// P1/P1 drag and pressure difference within 1 %, lift within 5 %; isoparametric Taylor-Hood
// with Newton: C_D within 0.01 %, C_L within 0.5 %, dp within 0.1 % in at most 6 solves.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "fsi/common/config.hpp"
#include "fsi/fluid/navier_stokes_fluid.hpp"

namespace {

TEST(DfgBenchmark, Dfg2d1WithinTolerances) {
  auto scene = fsi::Scene::load(FSI_FLUID_SOURCE_DIR "/configs/dfg_2d1.yaml", {"fluid.output.vtk_every=0"});
  const auto fluid = scene.section("fluid");
  ASSERT_EQ(fluid.get<std::string>("model"), "fem");
  fsi::FluidSetup setup;
  setup.dt = 1;
  setup.end_time = 1;
  fsi::fluid::NavierStokesFluid model;
  model.configure(fluid, setup);
  scene.check_all_used("fluid");
  EXPECT_EQ(model.interface().nodes(), 0u);
  const fsi::StepInfo info{1.0, 1.0, 1, 0};
  model.solve_step(info, {}, {});
  const auto probes = model.accept_step(info);
  const double cd = probes.at("cd"), cl = probes.at("cl"), dp = probes.at("dp");
  std::printf(
      "DFG 2D-1: C_D %.5f (ref 5.57954, %.3f%%)  C_L %.6f (ref 0.0106189, %.2f%%)  dp %.5f (ref 0.117520, %.3f%%)\n",
      cd, 100 * (cd / 5.57953523384 - 1), cl, 100 * (cl / 0.010618948146 - 1), dp, 100 * (dp / 0.11752016697 - 1));
  EXPECT_NEAR(cd, 5.57953523384, 0.01 * 5.57953523384);
  EXPECT_NEAR(cl, 0.010618948146, 0.05 * 0.010618948146);
  EXPECT_NEAR(dp, 0.11752016697, 0.01 * 0.11752016697);
}

TEST(DfgBenchmark, Dfg2d1TaylorHoodNewtonWithinTheTightTolerances) {
  auto scene = fsi::Scene::load(
      FSI_FLUID_SOURCE_DIR "/configs/dfg_2d1_p2p1.yaml",
      {"fluid.mesh.cache_dir=" + (std::filesystem::temp_directory_path() / "fsi_fluid_test_meshes").string()});
  const auto fluid = scene.section("fluid");
  ASSERT_EQ(fluid.get<std::string>("model"), "fem");
  fsi::FluidSetup setup;
  setup.dt = 1;
  setup.end_time = 1;
  fsi::fluid::NavierStokesFluid model;
  model.configure(fluid, setup);
  scene.check_all_used("fluid");
  ASSERT_TRUE(model.solver().mesh().quadratic());
  const fsi::StepInfo info{1.0, 1.0, 1, 0};
  model.solve_step(info, {}, {});
  const auto probes = model.accept_step(info);
  const double cd = probes.at("cd"), cl = probes.at("cl"), dp = probes.at("dp");
  std::printf(
      "DFG 2D-1 P2/P1 (%d unknowns, %g Newton solves): C_D %.6f (%.4f%%)  C_L %.7f (%.3f%%)  dp %.6f (%.4f%%)\n",
      model.solver().dofs(), probes.at("nonlinear_iterations"), cd, 100 * (cd / 5.57953523384 - 1), cl,
      100 * (cl / 0.010618948146 - 1), dp, 100 * (dp / 0.11752016697 - 1));
  EXPECT_NEAR(cd, 5.57953523384, 1e-4 * 5.57953523384);
  EXPECT_NEAR(cl, 0.010618948146, 5e-3 * 0.010618948146);
  EXPECT_NEAR(dp, 0.11752016697, 1e-3 * 0.11752016697);
  EXPECT_LE(probes.at("nonlinear_iterations"), 6);
}

TEST(DfgBenchmark, P1OnlyKeysAreRejectedForTaylorHood) {
  for (const char* key : {"fluid.stabilisation.pspg=true", "fluid.stabilisation.lsic_scale=1.0", "fluid.element=p3"}) {
    auto scene = fsi::Scene::load(FSI_FLUID_SOURCE_DIR "/configs/dfg_2d1_p2p1.yaml", {"fluid.mesh.size=0.2", key});
    fsi::fluid::NavierStokesFluid model;
    EXPECT_THROW(model.configure(scene.section("fluid"), fsi::FluidSetup{}), fsi::ConfigError) << key;
  }
}

TEST(DfgBenchmark, UnknownSceneKeyIsRejected) {
  auto scene =
      fsi::Scene::load(FSI_FLUID_SOURCE_DIR "/configs/dfg_2d1.yaml", {"fluid.mesh.size=0.08", "fluid.scheme=bdf3"});
  fsi::fluid::NavierStokesFluid model;
  EXPECT_THROW(model.configure(scene.section("fluid"), fsi::FluidSetup{}), fsi::ConfigError);
}

TEST(DfgBenchmark, GeoWithoutSurfaceNamesTheGeoNotTheCachedMesh) {
  // gmsh meshes a .geo with lines only without complaint; the message must name the .geo
  // (file and line of the scene key), not the cache file it wrote.
  const auto dir = std::filesystem::temp_directory_path() / "fsi_fluid_test_nosurface";
  std::filesystem::create_directories(dir);
  {
    std::ofstream geo(dir / "lines_only.geo");
    geo << "Point(1) = {0, 0, 0, h};\nPoint(2) = {1, 0, 0, h};\nLine(1) = {1, 2};\nPhysical Line(\"inlet\") = {1};\n";
  }
  auto scene = fsi::Scene::load(FSI_FLUID_SOURCE_DIR "/configs/dfg_2d1.yaml",
                                {"fluid.mesh.geo=" + (dir / "lines_only.geo").string(), "fluid.mesh.size=0.5",
                                 "fluid.mesh.cache_dir=" + (dir / "cache").string()});
  fsi::fluid::NavierStokesFluid model;
  try {
    model.configure(scene.section("fluid"), fsi::FluidSetup{});
    FAIL() << "a .geo without a surface was accepted";
  } catch (const fsi::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'fluid.mesh.geo'"), std::string::npos) << what;
    EXPECT_NE(what.find("needs a plane surface"), std::string::npos) << what;
    EXPECT_EQ(what.rfind("cache", 0), std::string::npos) << what;  // starts with the scene, not the cache
  }
}

}  // namespace
