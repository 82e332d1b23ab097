// A glTF scene's own lights (KHR_lights_punctual) travel through `import` into the pack's
// manifest and light `render`, unless --sun overrides them.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <stb_image.h>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"
#include "world/pack.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

// A 20 m floor quad at y = 0 and a point light 1 m above its centre.
fs::path writeLitFloor(const fs::path& dir) {
  const float v[12] = {-10, 0, -10, 10, 0, -10, 10, 0, 10, -10, 0, 10};
  const std::uint16_t idx[6] = {0, 2, 1, 0, 3, 2};
  std::ofstream bin(dir / "floor.bin", std::ios::binary);
  bin.write(reinterpret_cast<const char*>(v), sizeof v);
  bin.write(reinterpret_cast<const char*>(idx), sizeof idx);
  bin.close();
  nlohmann::json j;
  j["asset"] = {{"version", "2.0"}};
  j["extensionsUsed"] = {"KHR_lights_punctual"};
  j["buffers"] = {{{"uri", "floor.bin"}, {"byteLength", sizeof v + sizeof idx}}};
  j["bufferViews"] = {{{"buffer", 0}, {"byteLength", sizeof v}},
                      {{"buffer", 0}, {"byteOffset", sizeof v}, {"byteLength", sizeof idx}}};
  j["accessors"] = {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"},
                     {"min", {-10, 0, -10}}, {"max", {10, 0, 10}}},
                    {{"bufferView", 1}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}};
  j["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}};
  j["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "point"}, {"color", {1.0, 0.9, 0.8}}, {"intensity", 6.0}}};
  j["nodes"] = {{{"mesh", 0}},
                {{"translation", {0.0, 1.0, 0.0}},
                 {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}};
  j["scenes"] = {{{"nodes", {0, 1}}}};
  const fs::path file = dir / "floor.gltf";
  std::ofstream(file) << j.dump();
  return file;
}

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  double luminance(int x, int y) const {
    const unsigned char* p = &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
  }
  double mean() const {
    double sum = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) sum += luminance(x, y);
    return sum / (width * height);
  }
};

Image readPng(const fs::path& file) {
  Image im;
  int comp = 0;
  unsigned char* data = stbi_load(file.c_str(), &im.width, &im.height, &comp, 3);
  if (!data) return im;
  im.rgb.assign(data, data + std::size_t(im.width) * std::size_t(im.height) * 3);
  stbi_image_free(data);
  return im;
}

TEST(CliSceneLights, ImportedLightsAreStoredAndLightTheRender) {
  const fs::path dir = test::scratchDir("cli-scene-lights");
  const fs::path gltf = writeLitFloor(dir);
  const fs::path world = dir / "world";
  test::CliResult imp =
      test::runCli(SDFSTREAM_CLI, "import " + gltf.string() + " -o " + world.string() +
                                      " --voxel 0.05");
  ASSERT_EQ(imp.exitCode, 0) << imp.err;
  const PackManifest m = readManifest(world);
  ASSERT_EQ(m.lights.size(), 1u);
  EXPECT_EQ(m.lights[0].type, SceneLight::Type::Point);
  EXPECT_NEAR(glm::length(m.lights[0].position - glm::dvec3(0, 1, 0)), 0.0, 1e-9);
  EXPECT_FLOAT_EQ(m.lights[0].intensity, 6.0f);

  // Looking straight down at the floor, direct light only (CPU reference): the pack's point
  // light against an explicit --sun with no irradiance (sky alone), both under the same sky.
  const std::string view = " --cpu --width 48 --height 48 --camera 0,4,0.001,0,0,0,70";
  test::CliResult own =
      test::runCli(SDFSTREAM_CLI, "render " + world.string() + " -o " + (dir / "own.png").string() + view);
  ASSERT_EQ(own.exitCode, 0) << own.err;
  test::CliResult dark = test::runCli(
      SDFSTREAM_CLI,
      "render " + world.string() + " -o " + (dir / "dark.png").string() + view + " --sun 0,-1,0,0");
  ASSERT_EQ(dark.exitCode, 0) << dark.err;
  const Image lit = readPng(dir / "own.png"), unlit = readPng(dir / "dark.png");
  ASSERT_EQ(lit.width, 48);
  ASSERT_EQ(unlit.width, 48);
  EXPECT_GT(lit.mean(), unlit.mean() + 10.0) << "the pack's light does not light the render";
  // A point light 1 m above the centre: the floor under it is brighter than near the edges.
  EXPECT_GT(lit.luminance(24, 24), lit.luminance(24, 4) + 10.0);

  // fly takes the same lights (direct light only on the CPU reference), descending towards the
  // light, looking down at the floor around it; 60 paced frames (2 s) so the tiles have
  // streamed in by the last, the one compared.
  std::ofstream(dir / "path.txt") << "0 3 -4\n0 1 -1\n";
  const std::string flyArgs = " --cpu --frames 60 --width 48 --height 27 --image-every 59"
                              " --path " + (dir / "path.txt").string();
  test::CliResult flyOwn = test::runCli(
      SDFSTREAM_CLI, "fly " + world.string() + " -o " + (dir / "fly-own").string() + flyArgs);
  ASSERT_EQ(flyOwn.exitCode, 0) << flyOwn.err;
  test::CliResult flyDark =
      test::runCli(SDFSTREAM_CLI, "fly " + world.string() + " -o " + (dir / "fly-dark").string() +
                                      flyArgs + " --sun 0,-1,0,0");
  ASSERT_EQ(flyDark.exitCode, 0) << flyDark.err;
  const Image flyLit = readPng(dir / "fly-own" / "frames" / "frame-0059.png");
  const Image flyUnlit = readPng(dir / "fly-dark" / "frames" / "frame-0059.png");
  ASSERT_EQ(flyLit.width, 48);
  ASSERT_EQ(flyUnlit.width, 48);
  EXPECT_GT(flyLit.mean(), flyUnlit.mean() + 5.0) << "fly ignores the pack's light";
}

}  // namespace
}  // namespace sdfstream
