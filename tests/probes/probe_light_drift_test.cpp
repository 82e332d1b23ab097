// A sun that moves a fraction of a degree a frame (time of day): as a light change every frame it
// woke every probe (vigilant) every frame, so the field ran at its whole ray budget; as a drift
// (ProbeFrameInputs::lightsDrifting) no probe wakes and sleeping probes follow the light at
// their refreshes. Checked: the drift updates a fraction of the probes, ends as close to a field
// converged under the final sun as waking every frame does, and the GPU equals the CPU
// reference through drifting frames. Plus the rule that tells a drift from a change.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "gi/light_drift.h"
#include "tests/probes/gi_harness.h"
#include "tests/probes/probe_field_checks.h"
#include "tests/support/analytic_stack.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::probe {
namespace {

class ProbeLightDriftTest : public test::GpuTest {};

constexpr std::uint32_t kGrey = 170u | 170u << 8 | 170u << 16 | 255u << 24;

// A floor (y < 40), a wall along x and a pillar: what they receive and bounce depends on where
// the sun stands.
test::AnalyticStack courtyard() {
  return test::AnalyticStack(
      1,
      [](glm::vec3 p, float) {
        const float floor = p.y - 40.0f;
        const float wall = -test::insideBox(glm::vec3(30, 30, 70), glm::vec3(100, 70, 76))(p);
        const float pillar = -test::insideBox(glm::vec3(50, 30, 40), glm::vec3(58, 80, 48))(p);
        return std::min({floor, wall, pillar});
      },
      [](glm::vec3) { return glm::uvec2(kGrey, 0u); });
}

ProbeFieldSettings field() {
  ProbeFieldSettings s;
  s.spacingBricks = 2;  // 9³ probes
  s.raysPerProbe = 32;
  return s;
}

// The sun 45 degrees up, turned `degrees` about the vertical.
glm::vec3 sunAt(float degrees) {
  const float a = glm::radians(degrees);
  return glm::vec3(std::cos(a), -1.0f, std::sin(a));
}

std::vector<glm::vec3> probeMeans(ProbeField& f, const ProbeFieldSettings& s,
                                  std::vector<bool>& live) {
  const auto irr = f.downloadIrradiance();
  const auto data = f.downloadProbeData();
  std::vector<glm::vec3> out(data.size());
  live.assign(data.size(), false);
  for (std::uint32_t g = 0; g < data.size(); ++g) {
    live[g] = std::uint32_t(data[g].w + 0.5f) != gpu_shared::kProbeOff;
    out[g] = test::meanProbeIrradiance(irr, g, s.irradianceGamma);
  }
  return out;
}

float luminance(glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

struct SweepResult {
  double updatedPerFrame = 0.0;
  std::vector<glm::vec3> means, before;  // at the end; before the sun moved
  std::vector<bool> live;
};

// 70 frames under the first sun (the field settles: vigilant for 32, then asleep where quiet), then
// `frames` frames turning it `step` degrees a frame, each a light change (drift = false) or a
// drift.
SweepResult sweep(gpu::Context& ctx, const test::AnalyticStack& scene, bool drift, int frames,
                  float step) {
  const CascadeStackImage& img = scene.image;
  test::GiHarness h(ctx, field(), 1, false, true);
  ProbeFrameInputs in;
  in.cameraWorld = glm::dvec3(64.0, 50.0, 64.0);
  std::uint64_t frame = 0;
  h.lights = test::sunLights(img, sunAt(0.0f), 3.0f);
  for (; frame < 70; ++frame) {
    in.lightsChanged = frame == 0;
    h.step(img, in, frame, frame == 0);
  }
  SweepResult r;
  r.before = probeMeans(*h.gpuField, h.settings, r.live);
  for (int k = 1; k <= frames; ++k, ++frame) {
    h.lights = test::sunLights(img, sunAt(step * float(k)), 3.0f);
    in.lightsChanged = !drift;
    in.lightsDrifting = drift;
    h.step(img, in, frame, false);
    r.updatedPerFrame += double(h.gpuField->lastStats().probesUpdated) / frames;
  }
  r.means = probeMeans(*h.gpuField, h.settings, r.live);
  return r;
}

// Mean relative difference of the live probes' mean irradiance (luminance) to the reference's.
double meanRelative(const std::vector<glm::vec3>& a, const std::vector<bool>& live,
                    const SweepResult& ref) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t g = 0; g < a.size(); ++g) {
    if (!live[g] || !ref.live[g]) continue;
    const float e = luminance(ref.means[g]);
    if (e < 1e-3f) continue;
    sum += std::abs(luminance(a[g]) - e) / e;
    ++n;
  }
  return n ? sum / double(n) : 1.0;
}

// A sun turning 0.3 degree a frame over a settled field, 24 degrees in all: as a drift it updates
// about half the probes that waking every probe every frame does (fewer at a slower pace: a
// sleeping probe wakes only when its refresh sees more change than the sleep threshold), and
// ends as close to the field converged under the final sun (sleeping probes' refreshes follow
// the light; the probes the change keeps awake update every frame).
TEST_F(ProbeLightDriftTest, AMovingSunAsADriftUpdatesFewProbesAndEndsAsClose) {
  const test::AnalyticStack scene = courtyard();
  constexpr int kFrames = 80;
  constexpr float kStep = 0.3f;
  const SweepResult woken = sweep(ctx(), scene, false, kFrames, kStep);
  const SweepResult drifted = sweep(ctx(), scene, true, kFrames, kStep);
  SweepResult reference;  // the final sun from the start: vigilant, then awake, 100 frames
  {
    test::GiHarness h(ctx(), field(), 1, false, true);
    h.lights = test::sunLights(scene.image, sunAt(kStep * kFrames), 3.0f);
    ProbeFrameInputs in;
    in.cameraWorld = glm::dvec3(64.0, 50.0, 64.0);
    for (std::uint64_t f = 0; f < 100; ++f) {
      in.lightsChanged = f == 0;
      h.step(scene.image, in, f, f == 0);
    }
    reference.means = probeMeans(*h.gpuField, h.settings, reference.live);
  }
  const double errWoken = meanRelative(woken.means, woken.live, reference);
  const double errDrifted = meanRelative(drifted.means, drifted.live, reference);
  const double moved = meanRelative(woken.before, woken.live, reference);  // the turn's effect
  std::printf(
      "[figures] sun turning %.1f deg a frame for %d frames (9^3 probes x 32 rays): probes "
      "updated a frame %.1f as light changes, %.1f as a drift; mean relative difference to the "
      "field converged under the final sun: %.3f woken, %.3f drifting (before the turn: %.3f)\n",
      kStep, kFrames, woken.updatedPerFrame, drifted.updatedPerFrame, errWoken, errDrifted, moved);
  EXPECT_GT(moved, 0.08);                                           // the turn matters
  EXPECT_LT(drifted.updatedPerFrame, 0.6 * woken.updatedPerFrame);  // fewer at a slower pace
  EXPECT_LT(errDrifted, errWoken + 0.02);
  EXPECT_LT(errDrifted, 0.5 * moved);
}

// The drift's blend and classification rules (sleeping probes' lower hysteresis, the calm
// drifting update) are the same code on both sides: GPU == CPU through drifting frames.
TEST_F(ProbeLightDriftTest, GpuMatchesCpuThroughDriftingFrames) {
  const test::AnalyticStack scene = courtyard();
  ProbeFieldSettings s = field();
  s.spacingBricks = 4;  // 5³ probes: the CPU reference traces every ray
  s.raysPerProbe = 16;
  test::GiHarness h(ctx(), s, 1);
  ProbeFrameInputs in;
  in.cameraWorld = glm::dvec3(64.0, 50.0, 64.0);
  std::uint32_t sleeping = 0, drifting = 0;
  for (std::uint64_t frame = 0; frame < 48; ++frame) {
    h.lights =
        test::sunLights(scene.image, sunAt(frame < 24 ? 0.0f : 0.5f * float(frame - 23)), 3.0f);
    in.lightsChanged = frame == 0;
    in.lightsDrifting = frame >= 24;
    h.step(scene.image, in, frame, frame == 0);
    if (frame >= 24) {
      sleeping = std::max(sleeping, h.gpuField->lastStats().states[gpu_shared::kProbeSleeping]);
      drifting += in.lightsDrifting ? 1 : 0;
    }
  }
  const float irr = test::worstRelative<glm::vec4, 4>(h.cpuField->irradiance(),
                                                      h.gpuField->downloadIrradiance(), 1e-3f);
  const float data = test::worstRelative<glm::vec4, 4>(h.cpuField->probeData(),
                                                       h.gpuField->downloadProbeData(), 1e-3f);
  std::printf(
      "[figures] %u drifting frames, up to %u probes asleep: GPU vs CPU max rel diff "
      "irradiance %.2e, probe data %.2e\n",
      drifting, sleeping, irr, data);
  EXPECT_GT(sleeping, 0u);  // the drift's own rules ran
  EXPECT_LE(irr, 1e-2f);
  EXPECT_LE(data, 1e-5f);
  EXPECT_EQ(h.cpuField->lastStats().probesUpdated, h.gpuField->lastStats().probesUpdated);
}

TEST(LightDrift, TellsADriftFromAChange) {
  SceneLights a;
  SceneLight sun;
  sun.direction = glm::normalize(glm::vec3(1, -1, 0));
  sun.intensity = 3.0f;
  SceneLight lamp;
  lamp.type = SceneLight::Type::Point;
  lamp.position = glm::dvec3(1, 2, 3);
  a.lights = {sun, lamp};
  a.sky.zenith = glm::vec3(0.5f, 0.6f, 0.9f);
  const LightDriftLimits limits;  // 1 degree, 5%
  auto turned = [&](float degrees) {
    SceneLights b = a;
    const float r = glm::radians(degrees);
    const glm::vec3 d = b.lights[0].direction;
    b.lights[0].direction = glm::vec3(d.x * std::cos(r) - d.z * std::sin(r), d.y,
                                      d.x * std::sin(r) + d.z * std::cos(r));
    return b;
  };
  EXPECT_TRUE(isLightDrift(a, a, limits));
  EXPECT_TRUE(isLightDrift(a, turned(0.5f), limits));
  EXPECT_FALSE(isLightDrift(a, turned(2.0f), limits));
  SceneLights b = a;
  b.lights[0].intensity *= 1.03f;
  EXPECT_TRUE(isLightDrift(a, b, limits));
  b.lights[0].intensity = a.lights[0].intensity * 1.10f;
  EXPECT_FALSE(isLightDrift(a, b, limits));
  b = a;
  b.lights[1].position.x += 0.01;  // a moving lamp lights new places: a change
  EXPECT_FALSE(isLightDrift(a, b, limits));
  b = a;
  b.lights.pop_back();
  EXPECT_FALSE(isLightDrift(a, b, limits));
  b = a;
  b.sky.zenith *= 1.2f;
  EXPECT_FALSE(isLightDrift(a, b, limits));
  b = a;
  b.lights[0].color = glm::vec3(1.0f, 0.98f, 0.97f);
  EXPECT_TRUE(isLightDrift(a, b, limits));
  EXPECT_FALSE(isLightDrift(a, turned(0.5f), LightDriftLimits{0.0f, 0.05f}));  // off
}

}  // namespace
}  // namespace sdfstream::probe
