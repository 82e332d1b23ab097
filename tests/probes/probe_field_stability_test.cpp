// Stability and convergence of the probe field: a long run with a moving light and camera stays
// finite, bounded and deterministic; after a light switches off and on the field follows in a few
// frames.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <gtest/gtest.h>

#include "tests/probes/gi_harness.h"
#include "tests/probes/probe_field_checks.h"
#include "tests/support/analytic_stack.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::probe {
namespace {

class ProbeFieldStabilityTest : public test::GpuTest {};

// A closed grey room [48,80]³ (cascade-0 voxels, voxel 1 m; walls 4 voxels thick, empty space
// around it) lit by one point light.
constexpr float kLo = 48.0f, kHi = 80.0f;
constexpr std::uint32_t kGreyByte = 170;
constexpr std::uint32_t kGrey = kGreyByte | kGreyByte << 8 | kGreyByte << 16 | 255u << 24;

struct Room {
  test::AnalyticStack stack{1,
                            [](glm::vec3 p, float) {
                              const float inner = test::insideBox(glm::vec3(kLo), glm::vec3(kHi))(p);
                              const float outer = test::insideBox(glm::vec3(kLo - 4.0f), glm::vec3(kHi + 4.0f))(p);
                              return std::max(-outer, inner);
                            },
                            [](glm::vec3) { return glm::uvec2(kGrey, 0u); }};
};

// Small enough for 10,000 lavapipe frames in the suite: 9³ probes, 8 rays each.
ProbeFieldSettings smallField() {
  ProbeFieldSettings s;
  s.spacingBricks = 2;
  s.raysPerProbe = 8;
  return s;
}

std::vector<gpu_shared::GpuLight> pointLight(const CascadeStackImage& img, glm::vec3 p, float intensity) {
  sdfstream::SceneLight l;
  l.type = sdfstream::SceneLight::Type::Point;
  l.position = glm::dvec3(p);
  l.intensity = intensity;
  return sdfstream::toGpu(std::vector<sdfstream::SceneLight>{l}, img);
}

// The light circles the room 4 voxels or more from every wall, moving every 40 frames; the
// camera circles too (changing the probes' priorities). Checked every 500 frames: no NaN or Inf
// in any irradiance or depth texel, and every probe's mean irradiance under the furnace bound
//   E <= rho / (1 - rho) * E_direct,max,   E_direct,max = I / d_min²  (d_min = 4 voxels = 4 m):
// a probe sees surfaces of radiance L <= rho/pi (E_direct,max + pi L_max), so L_max <=
// rho E_direct,max / (pi (1 - rho)), and E = integral of L cos <= pi L_max.
TEST_F(ProbeFieldStabilityTest, TenThousandFramesStayFiniteAndBounded) {
  Room room;
  const CascadeStackImage& img = room.stack.image;
  test::GiHarness h(ctx(), smallField(), 1, false, true);
  const float intensity = 400.0f;
  const double rho = std::pow((kGreyByte / 255.0 + 0.055) / 1.055, 2.4);
  const double bound = rho / (1.0 - rho) * intensity / 16.0;
  double worstMean = 0.0;
  std::size_t nonFinite = 0;
  ProbeFrameInputs in;
  const int frames = std::getenv("STABILITY_FRAMES") ? std::atoi(std::getenv("STABILITY_FRAMES")) : 10000;
  for (int frame = 0; frame < frames; ++frame) {
    const float a = 0.1f * float(frame / 40), b = 0.013f * float(frame);
    in.lightsChanged = frame % 40 == 0;
    if (in.lightsChanged) {
      const glm::vec3 p(64.0f + 11.0f * std::cos(a), 64.0f + 11.0f * std::sin(0.7f * a), 64.0f + 11.0f * std::sin(a));
      h.lights = pointLight(img, p, intensity);
    }
    in.cameraWorld = glm::dvec3(64.0 + 8.0 * std::cos(b), 60.0, 64.0 + 8.0 * std::sin(b));
    in.viewDirection = glm::vec3(-std::sin(b), 0.0f, std::cos(b));
    h.step(img, in, std::uint64_t(frame), frame == 0);
    if (std::getenv("STABILITY_TIMINGS")) {
      std::printf("frame %d:", frame);
      for (const auto& t : h.gpuField->lastTimings()) std::printf(" %s %.2f", t.name.c_str(), t.milliseconds);
      std::printf(" listed %u\n", h.gpuField->lastStats().probesUpdated);
    }
    if (frame % 500 != 499) continue;
    const auto irr = h.gpuField->downloadIrradiance();
    const auto depth = h.gpuField->downloadDepth();
    for (const glm::vec4& t : irr) nonFinite += !std::isfinite(t.x + t.y + t.z + t.w);
    for (const glm::vec2& t : depth) nonFinite += !std::isfinite(t.x + t.y);
    const auto data = h.gpuField->downloadProbeData();
    for (std::uint32_t g = 0; g < data.size(); ++g) {
      if (std::uint32_t(data[g].w + 0.5f) == gpu_shared::kProbeOff) continue;
      const glm::vec3 e = test::meanProbeIrradiance(irr, g, h.settings.irradianceGamma);
      worstMean = std::max(worstMean, double(std::max({e.x, e.y, e.z})));
    }
  }
  std::printf("[figures] stability: 10000 frames (light moved every 40, camera every frame): %zu non-finite texels; largest probe mean irradiance %.3f, furnace bound rho/(1-rho) I/d_min^2 = %.3f\n",
              nonFinite, worstMean, bound);
  EXPECT_EQ(nonFinite, 0u);
  EXPECT_GT(worstMean, 0.0);
  EXPECT_LE(worstMean, bound);
}

// Identical seeds and inputs on the same device give identical probes, bit for bit (the update
// list's order depends on GPU threads, the results must not).
TEST_F(ProbeFieldStabilityTest, IdenticalSeedsGiveIdenticalResults) {
  Room room;
  const CascadeStackImage& img = room.stack.image;
  std::vector<glm::vec4> runs[2];
  for (int run = 0; run < 2; ++run) {
    test::GiHarness h(ctx(), smallField(), 1, false, true);
    ProbeFrameInputs in;
    for (int frame = 0; frame < 300; ++frame) {
      in.lightsChanged = frame % 20 == 0;
      if (in.lightsChanged) h.lights = pointLight(img, glm::vec3(60.0f + 0.05f * float(frame), 66.0f, 62.0f), 300.0f);
      in.cameraWorld = glm::dvec3(64.0 + 0.01 * frame, 60.0, 64.0);
      h.step(img, in, std::uint64_t(frame), frame == 0);
    }
    runs[run] = h.gpuField->downloadIrradiance();
  }
  std::size_t differing = 0;
  for (std::size_t i = 0; i < runs[0].size(); ++i) differing += runs[0][i] != runs[1][i];
  std::printf("[figures] determinism: 300 frames twice, %zu of %zu irradiance texels differ\n", differing, runs[0].size());
  EXPECT_EQ(differing, 0u);
}

// Frames until the irradiance at receivers on the walls (their mean: the room's brightness) is
// within 5% of its converged value after the light switches off, and after it switches on again
// (goal <= 10 frames at the default settings: vigilant probes blend with hysteresis 0.3 for 32
// frames; with the bounce feedback the error shrinks by about h + (1 - h) rho = 0.58 per frame).
// Also reported: frames until every single receiver is within 5% (per-texel noise of 128 rays
// keeps a few receivers a little farther out for longer).
TEST_F(ProbeFieldStabilityTest, FollowsALightSwitchWithinTenFrames) {
  Room room;
  const CascadeStackImage& img = room.stack.image;
  test::GiHarness h(ctx(), ProbeFieldSettings{}, 1, false, true);
  const auto on = pointLight(img, glm::vec3(64.0f, 72.0f, 60.0f), 300.0f);
  const auto queries = test::boxWallQueries(glm::vec3(kLo), glm::vec3(kHi), 256, 9u);
  auto brightness = [&](const std::vector<glm::vec3>& e) {
    std::vector<double> m(e.size());
    for (std::size_t i = 0; i < e.size(); ++i) m[i] = (e[i].x + e[i].y + e[i].z) / 3.0;
    return m;
  };
  auto mean = [](const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return s / double(v.size());
  };
  ProbeFrameInputs in;
  in.cameraWorld = glm::dvec3(64.0);
  std::uint64_t frame = 0;
  h.lights = on;
  for (int i = 0; i < 100; ++i, ++frame) {
    in.lightsChanged = i == 0;
    h.step(img, in, frame, frame == 0);
  }
  const std::vector<double> lit = brightness(h.sampleGpu(queries));
  const double litMean = mean(lit);
  // Switch off (converged value 0: no emission, no sky), then on again; 40 frames each.
  int frames[2][2] = {{-1, -1}, {-1, -1}};  // [off, on][mean, every receiver]
  for (int phase = 0; phase < 2; ++phase) {
    h.lights = phase == 0 ? std::vector<gpu_shared::GpuLight>{} : on;
    for (int i = 0; i < 40; ++i, ++frame) {
      in.lightsChanged = i == 0;
      h.step(img, in, frame, false);
      const auto e = brightness(h.sampleGpu(queries));
      const double target = phase == 0 ? 0.0 : litMean;
      const bool meanWithin = std::abs(mean(e) - target) <= 0.05 * litMean;
      bool allWithin = true;
      for (std::size_t q = 0; q < e.size(); ++q)
        allWithin = allWithin && std::abs(e[q] - (phase == 0 ? 0.0 : lit[q])) <= 0.05 * lit[q];
      if (meanWithin && frames[phase][0] < 0) frames[phase][0] = i + 1;
      if (!meanWithin) frames[phase][0] = -1;  // must stay within
      if (allWithin && frames[phase][1] < 0) frames[phase][1] = i + 1;
    }
  }
  std::printf("[figures] convergence after a light switch (256 wall receivers, defaults): mean within 5%% after %d frames (off) and %d frames (on again), goal <= 10; every receiver within 5%% after %d (off) and %d (on) frames (-1: not within 40)\n",
              frames[0][0], frames[1][0], frames[0][1], frames[1][1]);
  EXPECT_GT(litMean, 0.0);
  EXPECT_GT(frames[0][0], 0);
  EXPECT_GT(frames[1][0], 0);
  EXPECT_LE(frames[0][0], 10);
  EXPECT_LE(frames[1][0], 10);
}

// A light switch's vigilance (ProbeFieldSettings::lightSwitchVigilantUpdates, at the catch-up's
// hysteresis lightSwitchHysteresis = 0 as GiSystem runs it) ends on the hit-cache rotations' mean:
// its last vigilantMeanUpdates updates take a running mean. Without it the field holds the last
// rotation's estimate, whose own bias against the converged field the calm hysteresis then keeps
// for tens of frames. Measured as the bench's light switch does: pointwise mean |E - E_on| at
// wall receivers, as a share of the switch's mean |E_on - E_off|, one frame after the vigilance;
// E_on is a field that settled for 200 frames (its own vigilance ended on the mean as well).
TEST_F(ProbeFieldStabilityTest, ALightSwitchsVigilanceEndsOnTheRotationsMean) {
  Room room;
  const CascadeStackImage& img = room.stack.image;
  const auto on = pointLight(img, glm::vec3(64.0f, 72.0f, 60.0f), 300.0f);
  const auto queries = test::boxWallQueries(glm::vec3(kLo), glm::vec3(kHi), 256, 9u);
  auto luminance = [](const std::vector<glm::vec3>& e) {
    std::vector<double> m(e.size());
    for (std::size_t i = 0; i < e.size(); ++i) m[i] = (e[i].x + e[i].y + e[i].z) / 3.0;
    return m;
  };
  auto meanAbsDiff = [](const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) d += std::abs(a[i] - b[i]);
    return d / double(a.size());
  };
  auto leftAfterSwitch = [&](std::uint32_t meanUpdates) {
    ProbeFieldSettings s = smallField();
    s.raysPerProbe = 32;  // few rays: each rotation's bias is plain to see
    s.vigilantMeanUpdates = meanUpdates;
    test::GiHarness h(ctx(), s, 1, false, true);
    ProbeFrameInputs in;
    in.cameraWorld = glm::dvec3(64.0);
    std::uint64_t frame = 0;
    h.lights = on;
    for (int i = 0; i < 200; ++i, ++frame) h.step(img, in, frame, frame == 0);
    const std::vector<double> lit = luminance(h.sampleGpu(queries));
    h.lights.clear();
    in.lightsChanged = true;
    for (int i = 0; i < 3; ++i, in.lightsChanged = false) h.step(img, in, frame++, false);
    const double change = meanAbsDiff(luminance(h.sampleGpu(queries)), lit);
    h.lights = on;
    in.lightsChanged = true;
    for (std::uint32_t i = 0; i <= s.lightSwitchVigilantUpdates; ++i) {
      in.lightSwitchCatchUp = i < s.lightSwitchVigilantUpdates;
      h.step(img, in, frame++, false);
      in.lightsChanged = false;
    }
    return meanAbsDiff(luminance(h.sampleGpu(queries)), lit) / change;
  };
  const double withMean = leftAfterSwitch(4);
  const double lastRotation = leftAfterSwitch(0);
  std::printf("[figures] light switch, 32 rays a probe: %.4f of the change left one frame after the vigilance with its closing mean over 4 updates, %.4f with the last rotation's estimate\n",
              withMean, lastRotation);
  EXPECT_LT(withMean, 0.05);
  EXPECT_LT(withMean, 0.75 * lastRotation);
}

}  // namespace
}  // namespace sdfstream::probe
