// Bounce cells (shaders/probe_trace.glsl, "Bounce cells"): a probe ray's multi-bounce term read
// from its hit's material voxel, looked up once for all the hits there and kept for a few
// updates, against the per-hit lookups it replaces; and the GPU passes against the CPU reference.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "tests/probes/gi_harness.h"
#include "tests/probes/probe_field_checks.h"
#include "tests/probes/probe_scenes.h"
#include "tests/support/gpu_test.h"
#include "tests/support/streamed_bunny.h"

namespace sdfstream::probe {
namespace {

class ProbeBounceCellsTest : public test::GpuTest {};

double meanBrightness(const std::vector<glm::vec3>& e) {
  double s = 0.0;
  for (const glm::vec3& v : e) s += (v.x + v.y + v.z) / 3.0;
  return s / double(std::max<std::size_t>(1, e.size()));
}

// The closed grey box [40,88]³ (albedo 0.8, no emission) lit by a point light at its centre: most
// of the light on its walls comes by bounces, so the bounce term decides the answer. Two fields,
// one whose cells serve several updates (the default) and one that looks every hit up itself,
// run 72 frames; from frame 18 (the end of the first light switch's vigilance) the cells serve
// several updates.
TEST_F(ProbeBounceCellsTest, CellsAgreeWithPerHitLookupsInAClosedBox) {
  constexpr float kLo = 40.0f, kHi = 88.0f;
  constexpr std::uint32_t kGrey = 204u | 204u << 8 | 204u << 16 | 255u << 24;  // 0.8 linear-ish
  test::AnalyticBox box(kLo, kHi, kGrey, 0u);
  const CascadeStackImage& img = box.image;
  ProbeFieldSettings cells;
  cells.spacingBricks = 2;
  cells.raysPerProbe = 32;
  cells.vigilantFrames = 8;
  ProbeFieldSettings perHit = cells;
  perHit.bounceCellUpdates = 0;
  ASSERT_GT(cells.bounceCellUpdates, 1u);  // the default serves several updates

  sdfstream::SceneLight l;
  l.type = sdfstream::SceneLight::Type::Point;
  l.position = glm::dvec3(0.5 * (kLo + kHi));
  l.intensity = 400.0;
  const auto lights = sdfstream::toGpu(std::vector<sdfstream::SceneLight>{l}, img);
  const auto queries = test::boxWallQueries(glm::vec3(kLo), glm::vec3(kHi), 512, 5u);

  struct Run {
    std::vector<glm::vec3> e;
    ProbeFieldStats last;
    double meanCells = 0.0, mostCells = 0.0;  // cells looked up per update, frames 40-71
  };
  auto run = [&](const ProbeFieldSettings& s) {
    test::GiHarness h(ctx(), s, 1, true, false);
    h.lights = lights;
    ProbeFrameInputs in;
    in.cameraWorld = glm::dvec3(0.5 * (kLo + kHi));
    Run r;
    for (std::uint64_t frame = 0; frame < 72; ++frame) {
      in.lightsChanged = frame == 0;
      h.step(img, in, frame);
      if (frame < 40) continue;
      const double cellsNow = double(h.cpuField->lastStats().bounceCells);
      r.meanCells += cellsNow / 32.0;
      r.mostCells = std::max(r.mostCells, cellsNow);
    }
    r.e = h.cpuField->sample(img, queries);
    r.last = h.cpuField->lastStats();
    return r;
  };
  const Run a = run(cells), b = run(perHit);
  double worst = 0.0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const double ea = (a.e[i].x + a.e[i].y + a.e[i].z) / 3.0;
    const double eb = (b.e[i].x + b.e[i].y + b.e[i].z) / 3.0;
    worst = std::max(worst, std::abs(ea - eb) / std::max(eb, 1e-6));
  }
  const double ma = meanBrightness(a.e), mb = meanBrightness(b.e);
  const std::uint32_t rays = a.last.raysCached + a.last.raysTraced;
  std::printf(
      "[figures] bounce cells vs per-hit lookups (closed grey box, point light, 72 frames): wall "
      "irradiance mean %.4f vs %.4f (%.2f%%), worst receiver %.2f%%; last update: %u rays, %u "
      "cells looked up, %u rays waited or looked up their own; cells looked up per update in "
      "frames 40-71: mean %.0f, most %.0f\n",
      ma, mb, 100.0 * (ma / mb - 1.0), 100.0 * worst, rays, a.last.bounceCells, a.last.bounceRays,
      a.meanCells, a.mostCells);
  EXPECT_GT(mb, 0.0);
  EXPECT_NEAR(ma / mb, 1.0, 0.01);
  EXPECT_LE(worst, 0.03);
  // The point of the cells: far fewer lookups than hits once they serve several updates.
  EXPECT_GT(a.last.bounceCells, 0u);
  EXPECT_LT(double(a.last.bounceCells), 0.25 * double(rays));
  EXPECT_LT(double(a.last.bounceRays), 0.5 * double(rays));
  EXPECT_EQ(b.last.bounceCells, 0u);
  EXPECT_EQ(b.last.bounceRays, 0u);
}

// Cells looked up in the same update (every cell hit, in the field's young updates) expire in
// different later updates: with every probe updated every frame (states off), the lookups per
// update stay near their mean instead of peaking every bounceCellUpdates-th update. One ray
// rotation, so that the same cells are hit in every update.
TEST_F(ProbeBounceCellsTest, CellsLookedUpTogetherExpireApart) {
  test::AnalyticBox box(40.0f, 88.0f, 204u | 204u << 8 | 204u << 16 | 255u << 24, 0u);
  const CascadeStackImage& img = box.image;
  ProbeFieldSettings s;
  s.spacingBricks = 2;
  s.raysPerProbe = 16;
  s.vigilantFrames = 4;
  s.states = false;
  s.cacheRotations = 1;  // the same rays every update: every cell is hit every update
  test::GiHarness h(ctx(), s, 1, true, false);
  h.lights = test::sunLights(img, glm::vec3(-0.3f, -1.0f, -0.4f), 3.0f);
  h.sky.zenith = glm::vec4(0.5f, 0.6f, 0.9f, 0.0f);
  ProbeFrameInputs in;
  in.cameraWorld = glm::dvec3(64.0);
  double mean = 0.0, most = 0.0;
  // A light switch's vigilance (18 updates) keeps the cells to one update first.
  for (std::uint64_t frame = 0; frame < 40; ++frame) {
    in.lightsChanged = frame == 0;
    h.step(img, in, frame);
    if (frame < 24) continue;
    const double cells = double(h.cpuField->lastStats().bounceCells);
    mean += cells / 16.0;
    most = std::max(most, cells);
  }
  std::printf(
      "[figures] bounce cells looked up per update, frames 24-39 (states off): mean %.0f, "
      "most %.0f\n",
      mean, most);
  EXPECT_GT(mean, 0.0);
  EXPECT_LE(most, 1.5 * mean);
}

// GPU == CPU with cells that serve several updates: the bunny field of ProbeFieldTest (3
// cascades, 5³ probes, 32 rays, sun + sky, hit cache), 12 frames with a vigilance of 2 frames
// and a light switch's of 2 updates.
// The cells' answers depend on neither side's ray order, so the bounds are ProbeFieldTest's for
// cached frames.
TEST_F(ProbeBounceCellsTest, GpuMatchesCpuWhileCellsServeSeveralUpdates) {
  test::StreamedBunny b = test::streamBunny();
  const CascadeStackImage img = b.stack->stackImage();
  ProbeFieldSettings s;
  s.spacingBricks = 4;
  s.raysPerProbe = 32;
  s.vigilantFrames = 2;
  s.lightSwitchVigilantUpdates = 2;
  test::GiHarness h(ctx(), s, 3);
  ProbeFrameInputs in = test::lightBunnyScene(h, img, b.camera);
  std::uint32_t cellsLookedUp[2] = {0, 0}, ownLookups[2] = {0, 0};
  for (std::uint64_t frame = 0; frame < 12; ++frame) {
    in.lightsChanged = frame == 0;
    h.step(img, in, frame);
    if (frame >= 2) {
      cellsLookedUp[0] += h.cpuField->lastStats().bounceCells;
      cellsLookedUp[1] += h.gpuField->lastStats().bounceCells;
      ownLookups[0] += h.cpuField->lastStats().bounceOwn;
      ownLookups[1] += h.gpuField->lastStats().bounceOwn;
    }
  }
  const float irr = test::worstRelative<glm::vec4, 4>(h.cpuField->irradiance(),
                                                      h.gpuField->downloadIrradiance(), 1e-3f);
  std::printf(
      "[figures] bounce cells GPU vs CPU (bunny, 12 frames, cells serve several updates from frame "
      "2): "
      "max rel diff irradiance %.2e; cells looked up in frames 2-11 %u (CPU) / %u (GPU), rays "
      "that looked up their own %u / %u\n",
      irr, cellsLookedUp[0], cellsLookedUp[1], ownLookups[0], ownLookups[1]);
  EXPECT_LE(irr, 2e-2f);
  EXPECT_GT(cellsLookedUp[0], 0u);
  // The same cells go stale on both sides; a grazing ray may hit on one side only.
  EXPECT_NEAR(double(cellsLookedUp[1]), double(cellsLookedUp[0]), 0.01 * double(cellsLookedUp[0]));
  EXPECT_GT(ownLookups[0], 0u);
  EXPECT_NEAR(double(ownLookups[1]), double(ownLookups[0]), 0.01 * double(ownLookups[0]));
}

}  // namespace
}  // namespace sdfstream::probe
