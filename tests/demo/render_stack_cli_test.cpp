// `sdfstream render` streams the whole cascade stack: a world larger than one cascade is framed
// whole by the default camera, where a single cascade shows a fragment of it; a roofed interior's
// default view looks into it rather than at its roof. With --mesh the
// primary surfaces are the source triangles, rasterized; bad use of it is a one-line error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <utility>

#include <glm/glm.hpp>

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

// "camera px,py,pz,..." of render's summary line.
glm::dvec3 renderedCameraPosition(const std::string& out) {
  std::smatch m;
  const std::string number = "(-?[0-9.]+)";
  if (!std::regex_search(out, m, std::regex("camera " + number + "," + number + "," + number)))
    return glm::dvec3(NAN);
  return {std::stod(m[1]), std::stod(m[2]), std::stod(m[3])};
}

// A roofed room open on its +x side (floor, roof, three walls of boxes), and the same floor with
// nothing over it: seen from above, the first is all roof, so the default view goes to where it
// sees in (through the open side); the second keeps the overview from above.
TEST(RenderStackCli, DefaultViewOfARoofedInteriorLooksIntoIt) {
  const auto dir = test::scratchDir("render-interior");
  const std::string room = R"({"boxes": [
    {"min": [0, 0, 0], "max": [6, 0.2, 4], "albedo": [0.7, 0.7, 0.7]},
    {"min": [0, 2.8, 0], "max": [6, 3, 4], "albedo": [0.5, 0.3, 0.2]},
    {"min": [0, 0.2, 0], "max": [0.2, 2.8, 4], "albedo": [0.8, 0.8, 0.8]},
    {"min": [0, 0.2, 0], "max": [6, 2.8, 0.2], "albedo": [0.8, 0.1, 0.1]},
    {"min": [0, 0.2, 3.8], "max": [6, 2.8, 4], "albedo": [0.1, 0.8, 0.1]},
    {"min": [2.5, 0.2, 1.5], "max": [3.5, 1.2, 2.5], "albedo": [0.9, 0.9, 0.9]}]})";
  const std::string open = R"({"boxes": [
    {"min": [0, 0, 0], "max": [6, 0.2, 4], "albedo": [0.7, 0.7, 0.7]},
    {"min": [2.5, 0.2, 1.5], "max": [3.5, 1.2, 2.5], "albedo": [0.9, 0.9, 0.9]}]})";
  for (const auto& [name, json] : {std::pair{"room", room}, std::pair{"open", open}}) {
    const auto layout = dir / (std::string(name) + ".json");
    std::ofstream(layout) << json;
    const auto world = (dir / name).string();
    const test::CliResult imp =
        test::runCli(SDFSTREAM_CLI, "import " + layout.string() + " -o " + world + " --voxel 0.05");
    ASSERT_EQ(imp.exitCode, 0) << imp.err;
    const test::CliResult r =
        test::runCli(SDFSTREAM_CLI, "render " + world + " -o " + (dir / name).string() +
                                        ".png --width 96 --height 54 --gi off");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const glm::dvec3 camera = renderedCameraPosition(r.out);
    if (std::string(name) == "room") {
      // Below the roof, level with the room, on the open side (inside or outside it).
      EXPECT_LT(camera.y, 2.8) << r.out;
      EXPECT_GT(camera.x, 3.0) << r.out;
      EXPECT_GT(camera.z, 0.2) << r.out;
      EXPECT_LT(camera.z, 3.8) << r.out;
      EXPECT_GE(hitFraction(r.out), 0.6) << r.out;
    } else {
      EXPECT_GT(camera.y, 3.0) << "the open floor keeps the view from above: " << r.out;
    }
  }
}

}  // namespace
}  // namespace sdfstream
