// `sdfstream render` streams the whole cascade stack: a world larger than one cascade is framed
// whole by the default camera, where a single cascade shows a fragment of it. With --mesh the
// primary surfaces are the source triangles, rasterized; bad use of it is a one-line error.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <string>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {

// "N/M rays hit" of render's summary line, as the fraction N/M (-1 when absent).
double hitFraction(const std::string& out) {
  std::smatch m;
  if (!std::regex_search(out, m, std::regex("([0-9]+)/([0-9]+) rays hit"))) return -1.0;
  return std::stod(m[1]) / std::stod(m[2]);
}

TEST(RenderStackCli, AWorldLargerThanOneCascadeIsFramedWhole) {
  const auto dir = test::scratchDir("render-stack");
  // The 2 m Cornell box at 1 cm: one 128^3 cascade of LOD 0 spans 1.28 m of it.
  const auto input = test::sourceDir() / "tests/gltf/data/cornell-quantized.glb";
  const auto world = (dir / "world").string();
  const test::CliResult imp =
      test::runCli(SDFSTREAM_CLI, "import " + input.string() + " -o " + world + " --voxel 0.01");
  ASSERT_EQ(imp.exitCode, 0) << imp.err;
  const std::string common = " --width 96 --height 54 --gi off";
  const test::CliResult stack = test::runCli(
      SDFSTREAM_CLI, "render " + world + " -o " + (dir / "stack.png").string() + common);
  ASSERT_EQ(stack.exitCode, 0) << stack.err;
  const test::CliResult one =
      test::runCli(SDFSTREAM_CLI, "render " + world + " -o " + (dir / "one.png").string() + common +
                                      " --cascades 1");
  ASSERT_EQ(one.exitCode, 0) << one.err;
  const double all = hitFraction(stack.out), single = hitFraction(one.out);
  EXPECT_GE(all, 0.35) << stack.out;
  EXPECT_GE(all, 5.0 * single) << stack.out << one.out;
}

// "raster primary X ms (N triangles)" of render's summary line: N (-1 when absent).
long rasterTriangles(const std::string& out) {
  std::smatch m;
  if (!std::regex_search(out, m, std::regex("raster primary [0-9.]+ ms \\(([0-9]+) triangles\\)")))
    return -1;
  return std::stol(m[1]);
}

TEST(RenderStackCli, MeshPrimaryRastersTheSourceTriangles) {
  const auto dir = test::scratchDir("render-mesh");
  const auto input = test::sourceDir() / "tests/gltf/data/cornell-quantized.glb";
  const auto world = (dir / "world").string();
  const test::CliResult imp =
      test::runCli(SDFSTREAM_CLI, "import " + input.string() + " -o " + world + " --voxel 0.04");
  ASSERT_EQ(imp.exitCode, 0) << imp.err;
  const std::string common = " --width 96 --height 54 --gi off";
  const test::CliResult sdf =
      test::runCli(SDFSTREAM_CLI, "render " + world + " -o " + (dir / "sdf.png").string() + common);
  ASSERT_EQ(sdf.exitCode, 0) << sdf.err;
  const test::CliResult raster =
      test::runCli(SDFSTREAM_CLI, "render " + world + " -o " + (dir / "raster.png").string() +
                                      common + " --mesh " + input.string());
  ASSERT_EQ(raster.exitCode, 0) << raster.err;
  EXPECT_GT(rasterTriangles(raster.out), 0) << raster.out;
  EXPECT_EQ(rasterTriangles(sdf.out), -1) << sdf.out;
  // The same box either way: the SDF's surface stands up to a voxel proud of the triangles, so
  // its silhouette covers a little more.
  const double t = hitFraction(sdf.out), r = hitFraction(raster.out);
  EXPECT_GT(r, 0.2) << raster.out;
  EXPECT_NEAR(r / t, 1.0, 0.1) << sdf.out << raster.out;
  // --primary sdf keeps the trace even with --mesh.
  const test::CliResult back =
      test::runCli(SDFSTREAM_CLI, "render " + world + " -o " + (dir / "back.png").string() +
                                      common + " --mesh " + input.string() + " --primary sdf");
  ASSERT_EQ(back.exitCode, 0) << back.err;
  EXPECT_EQ(rasterTriangles(back.out), -1) << back.out;
}

TEST(RenderStackCli, MeshPrimaryMisuseIsAOneLineError) {
  const auto dir = test::scratchDir("render-mesh-errors");
  const auto input = test::sourceDir() / "tests/gltf/data/cornell-quantized.glb";
  const auto world = (dir / "world").string();
  ASSERT_EQ(
      test::runCli(SDFSTREAM_CLI, "import " + input.string() + " -o " + world + " --voxel 0.08")
          .exitCode,
      0);
  const std::string render = "render " + world + " -o " + (dir / "x.png").string() + " ";
  struct Case {
    std::string args, expect;
  };
  const Case cases[] = {
      {"--primary raster", "--primary raster needs --mesh"},
      {"--primary voxels --mesh " + input.string(), "--primary expects raster or sdf"},
      {"--cpu --mesh " + input.string(), "needs Vulkan"},
      {"--mesh " + (dir / "absent.glb").string(), "absent.glb"},
      {"--mesh " + (dir / "world/manifest.json").string(), "manifest.json"},
  };
  for (const Case& c : cases) {
    const test::CliResult r = test::runCli(SDFSTREAM_CLI, render + c.args);
    EXPECT_NE(r.exitCode, 0) << c.args;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png")) << c.args;
  }
}

}  // namespace
}  // namespace sdfstream
