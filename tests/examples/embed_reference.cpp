// The blocking path for the same world, camera path, lights, probe settings and grid as
// examples/embed (kept in step with it by hand: the example is meant to be read alone): a
// Context of its own, GiSystem::update every frame, then GiSystem::irradiance on the CPU side.
// Compares with the example's OUT/irradiance.pfm and fails above 1e-4 relative.
//   embed_reference WORLD EXAMPLE_PFM FRAMES
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "gi/gi_system.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/tile_loader.h"

namespace {
constexpr std::uint32_t kSize = 64;

std::vector<float> readPfm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  std::uint32_t w = 0, h = 0;
  float scale = 0;
  in >> magic >> w >> h >> scale;
  in.get();
  if (!in || magic != "PF" || w != kSize || h != kSize)
    throw std::runtime_error(path + ": not a 64x64 PF image");
  std::vector<float> rgb(std::size_t(w) * h * 3);
  in.read(reinterpret_cast<char*>(rgb.data()), std::streamsize(rgb.size() * 4));
  if (!in) throw std::runtime_error(path + ": truncated");
  return rgb;
}
}  // namespace

int main(int argc, char** argv) try {
  if (argc != 4)
    return std::fprintf(stderr, "usage: embed_reference WORLD EXAMPLE_PFM FRAMES\n"), 2;
  const int frames = std::stoi(argv[3]);
  auto ctx = sdfstream::gpu::Context::create();
  sdfstream::PackTileStore store(argv[1]);
  sdfstream::TileLoader loader(store);
  sdfstream::StreamingOptions so;
  so.cascades = 3;
  sdfstream::CascadeStack stack(store, loader, so);
  sdfstream::GiSettings settings;
  settings.probes.spacingBricks = 2;
  settings.probes.raysPerProbe = 64;
  settings.probes.shareSdfTests = false;  // the example samples per pixel
  sdfstream::GiSystem gi(*ctx, settings, std::uint32_t(so.cascades));
  sdfstream::SceneLights lights;
  lights.lights.push_back({});
  lights.lights[0].direction = glm::normalize(glm::vec3(0.4f, -1.0f, 0.3f));
  lights.lights[0].intensity = 3.0f;
  lights.sky.zenith = lights.sky.horizon = glm::vec3(0.3f, 0.4f, 0.6f);
  for (int f = 0; f < frames; ++f) {
    const glm::dvec3 camera(0.3 + 0.004 * f, 0.4, 1.4 - 0.003 * f);
    stack.update(camera);
    loader.waitIdle();
    const std::vector<std::uint32_t> dirty = stack.takeDirtySlots();
    sdfstream::probe::ProbeFrameInputs inputs;
    inputs.cameraWorld = camera;
    gi.update(stack, dirty, lights, inputs, std::uint64_t(f));
  }
  const sdfstream::CascadeStackImage image = stack.stackImage();
  const glm::vec3 origin = image.toStack(glm::dvec3(-0.35, 0.15, -0.35));
  const float step = float(0.02 / image.voxelSize0);
  std::vector<sdfstream::gpu_shared::ProbeQuery> queries(kSize * kSize);
  for (std::uint32_t i = 0; i < kSize * kSize; ++i) {
    const glm::vec3 p = origin + glm::vec3(float(i % kSize), 0.0f, float(i / kSize)) * step;
    queries[i] = {glm::vec4(p, 0.0f), glm::vec4(0, 1, 0, 0), glm::vec4(0, 1, 0, 0)};
  }
  const std::vector<glm::vec3> expected = gi.irradiance(queries);
  const std::vector<float> got = readPfm(argv[2]);
  double worst = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < expected.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double e = expected[i][k], g = got[3 * i + std::size_t(k)];
      sum += e;
      worst = std::max(worst, std::abs(g - e) / std::max(std::abs(e), 1e-3));
    }
  std::printf(
      "[figures] embed example vs blocking path: %zu pixels, worst relative difference %.3g, "
      "mean irradiance %.4f\n",
      expected.size(), worst, sum / (3.0 * double(expected.size())));
  if (!(sum > 0.0))
    return std::fprintf(stderr, "embed_reference: the blocking path's image is black\n"), 1;
  return worst <= 1e-4 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "embed_reference: %s\n", e.what());
  return 1;
}
