// The select pass (shaders/probe_select.glsl) when the probes wanted this frame outnumber the
// list: the classes that fit go whole, and the first class that does not fit gives the room left
// a share of its probes. Checked: the list then fills to within a few percent of its capacity
// (a stride of ceil(count / room) took as few as half), every probe of the overflowing class
// still comes up within a few frames, and the GPU takes exactly the probes the CPU reference does.
#include <algorithm>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "tests/probes/gi_harness.h"
#include "tests/probes/probe_field_checks.h"
#include "tests/support/analytic_stack.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::probe {
namespace {

class ProbeSelectTest : public test::GpuTest {};

constexpr std::uint32_t kGrey = 160u | 160u << 8 | 160u << 16 | 255u << 24;
constexpr std::uint32_t kRays = 32;

// A floor and a block: most of the 9³ probes live, all vigilant for their first frames (class 0).
test::AnalyticStack floorAndBlock() {
  return test::AnalyticStack(
      1,
      [](glm::vec3 p, float) {
        const float block = -test::insideBox(glm::vec3(50, 30, 50), glm::vec3(70, 60, 70))(p);
        return std::min(p.y - 40.0f, block);
      },
      [](glm::vec3) { return glm::uvec2(kGrey, 0u); });
}

ProbeFieldSettings fieldWithBudget(std::uint32_t rayBudget) {
  ProbeFieldSettings s;
  s.spacingBricks = 2;  // 9³ probes
  s.raysPerProbe = kRays;
  s.rayBudget = rayBudget;
  return s;
}

ProbeFrameInputs camera() {
  ProbeFrameInputs in;
  in.cameraWorld = glm::dvec3(64.0, 50.0, 20.0);
  in.viewDirection = glm::vec3(0.0f, 0.0f, 1.0f);
  return in;
}

TEST_F(ProbeSelectTest, AnOverflowingClassFillsTheListAndEveryProbeComesUp) {
  test::AnalyticStack scene = floorAndBlock();
  // How many probes a frame wants with room for all of them: every probe on frame 0, the live
  // ones (those outside the block) from frame 1 on.
  std::uint32_t wanted = 0;
  {
    test::GiHarness all(ctx(), fieldWithBudget(1u << 21), 1, true, false);
    for (int frame = 0; frame < 2; ++frame) {
      ProbeFrameInputs in = camera();
      in.lightsChanged = frame == 0;
      all.step(scene.image, in, std::uint64_t(frame));
      wanted = all.cpuField->lastStats().classCounts[0];
      ASSERT_EQ(all.cpuField->lastStats().probesUpdated, wanted);  // everything fits
    }
  }
  ASSERT_GT(wanted, 250u);
  // Room for 90% of them: the class overflows by a little, the case a stride served worst (2).
  const std::uint32_t capacity = wanted * 9 / 10;
  test::GiHarness h(ctx(), fieldWithBudget(capacity * kRays), 1);
  ASSERT_EQ(h.settings.listCapacity(1), capacity);
  std::vector<int> lastUpdated(9 * 9 * 9, -1);
  int longestWait = 0;
  constexpr int kFrames = 8;  // all within the vigilant phase: class 0 overflows every frame
  for (int frame = 0; frame < kFrames; ++frame) {
    ProbeFrameInputs in = camera();
    in.lightsChanged = frame == 0;
    h.step(scene.image, in, std::uint64_t(frame));
    const ProbeFieldStats& cs = h.cpuField->lastStats();
    const ProbeFieldStats& gs = h.gpuField->lastStats();
    ASSERT_GT(cs.classCounts[0], capacity) << "frame " << frame;
    std::printf("[figures] frame %d: %u wanted, room %u, listed %u (CPU) / %u (GPU)\n", frame,
                cs.classCounts[0], capacity, cs.probesUpdated, gs.probesUpdated);
    EXPECT_EQ(cs.probesUpdated, gs.probesUpdated) << "frame " << frame;
    const std::uint32_t listed = std::min(cs.probesUpdated, capacity);
    // The share aims 1/32 below the capacity; the taken count stays within a few probes of that
    // aim (the stride took 54% here) and below the capacity (no probe dropped by thread order).
    EXPECT_GE(listed, capacity * 94 / 100) << "frame " << frame;
    EXPECT_LE(cs.probesUpdated, capacity) << "frame " << frame;
    for (std::uint32_t g : h.cpuField->lastUpdateList()) {
      longestWait = std::max(longestWait, frame - lastUpdated[g]);
      lastUpdated[g] = frame;
    }
  }
  // Every live probe came up, none passed over twice in a row at shares of 0.8-0.9.
  std::uint32_t never = 0;
  for (std::uint32_t g = 0; g < lastUpdated.size(); ++g)
    if (lastUpdated[g] < 0 &&
        std::uint32_t(h.cpuField->probeData()[g].w + 0.5f) != gpu_shared::kProbeOff)
      ++never;
  std::printf(
      "[figures] %d frames at 80-90%% room: longest wait %d frames, %u live probes never listed\n",
      kFrames, longestWait, never);
  EXPECT_EQ(never, 0u);
  EXPECT_LE(longestWait, 2);
  // The GPU listed the same probes: a probe listed on one side only would differ by its whole
  // update (a first estimate against none); the bound is the GPU-vs-CPU test's.
  const float irr = test::worstRelative<glm::vec4, 4>(h.cpuField->irradiance(),
                                                      h.gpuField->downloadIrradiance(), 1e-3f);
  std::printf("[figures] GPU vs CPU irradiance after %d frames: max rel diff %.2e\n", kFrames, irr);
  EXPECT_LE(irr, 1e-2f);
}

}  // namespace
}  // namespace sdfstream::probe
