// ProbeFieldFrameBuilder: the ray pattern (the hit cache's rotation slots and their depth
// lists), what a frame's constants say about the light switch -- the catch-up's hysteresis and
// the vigilance counts the classify and blend passes read (shaders/probe_field.glsl,
// probeVigilantHysteresis).
#include <algorithm>

#include <gtest/gtest.h>

#include "gi/probe_field_frame.h"

namespace sdfstream::probe {
namespace {

CascadeStackImage oneCascade() {
  CascadeStackImage image;
  image.voxelSize0 = 1.0;
  gpu_shared::CascadeTraceParams p{};
  p.offsetScale = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  image.params.push_back(p);
  image.pageTables.assign(gpu_shared::kCascadePageCount, 0u);
  return image;
}

// With the hit cache the pattern holds every rotation slot (each probe steps through them by
// itself) and then each slot's depth lists, the same every frame; an update shift moves only
// the select pass's frame.
TEST(ProbeFieldFrame, TheCachesPatternHoldsEverySlotAndNeverChanges) {
  ProbeFieldSettings s;  // hit cache on, 4 rotations
  ProbeFieldFrameBuilder builder(s);
  const CascadeStackImage image = oneCascade();
  ProbeFrameInputs in;
  const ProbeFieldFrame first = builder.build(image, in, 5);
  in.updateShift = 2;
  const ProbeFieldFrame second = builder.build(image, in, 5);
  const std::size_t lists = std::size_t(gpu_shared::kProbeDepthInterior) *
                            gpu_shared::kProbeDepthInterior * gpu_shared::kProbeDepthListVec4s;
  const std::vector<glm::vec4>& pattern = *first.rayPattern;
  ASSERT_EQ(pattern.size(), 4 * (3 + lists));
  EXPECT_EQ(pattern, *second.rayPattern);
  EXPECT_EQ(first.constants.selection.z, 4u);
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      EXPECT_NE(pattern[3 * a], pattern[3 * b]);
      // Each slot's lists are its own rotation's: the first texel's lists differ somewhere.
      const auto la = pattern.begin() + 12 + a * lists;
      const auto lb = pattern.begin() + 12 + b * lists;
      EXPECT_FALSE(std::equal(la, la + lists, lb));
    }
  EXPECT_EQ(first.constants.options.y, 5u);
  EXPECT_EQ(second.constants.options.y, 7u);
}

// Without the cache, slot 0 holds a fresh rotation each frame (and each shifted update).
TEST(ProbeFieldFrame, WithoutTheCacheEachUpdateTakesAFreshRotation) {
  ProbeFieldSettings s;
  s.hitCache = false;
  ProbeFieldFrameBuilder builder(s);
  const CascadeStackImage image = oneCascade();
  ProbeFrameInputs in;
  const ProbeFieldFrame a = builder.build(image, in, 5);
  const ProbeFieldFrame b = builder.build(image, in, 6);
  in.updateShift = 1;
  const ProbeFieldFrame c = builder.build(image, in, 5);
  EXPECT_EQ(a.constants.selection.z, 1u);
  EXPECT_NE((*a.rayPattern)[0], (*b.rayPattern)[0]);
  EXPECT_EQ((*b.rayPattern)[0], (*c.rayPattern)[0]);  // frame 5 + shift 1 counts as frame 6
}

TEST(ProbeFieldFrame, TheCatchUpTakesItsOwnHysteresisAndTheVigilanceCounts) {
  ProbeFieldSettings s;
  s.vigilantHysteresis = 0.3f;
  s.lightSwitchHysteresis = 0.1f;
  s.vigilantFrames = 32;
  s.objectVigilantFrames = 8;
  s.lightSwitchVigilantUpdates = 16;
  s.vigilantMeanUpdates = 4;
  ProbeFieldFrameBuilder builder(s);
  const CascadeStackImage image = oneCascade();
  ProbeFrameInputs in;
  EXPECT_EQ(builder.build(image, in, 0).constants.view.w, 0.3f);
  in.lightSwitchCatchUp = true;
  const ProbeFieldFrame f = builder.build(image, in, 1);
  EXPECT_EQ(f.constants.view.w, 0.1f);
  const std::uint32_t w = f.constants.selection.w;
  EXPECT_EQ(w & 255u, 32u);
  EXPECT_EQ((w >> 8) & 255u, 8u);
  EXPECT_EQ((w >> 16) & 255u, 16u);
  EXPECT_EQ(w >> 24, 4u);
  // The caller's count wins (GiSystem scales it to the probes one update's list holds).
  in.lightSwitchVigilantUpdates = 7;
  EXPECT_EQ((builder.build(image, in, 2).constants.selection.w >> 16) & 255u, 7u);
  in.lightSwitchVigilantUpdates = 0;
  // 0 updates after a switch: the switch wakes probes for vigilantFrames, as new ones.
  s.lightSwitchVigilantUpdates = 0;
  ProbeFieldFrameBuilder plain(s);
  EXPECT_EQ((plain.build(image, in, 0).constants.selection.w >> 16) & 255u, 32u);
}

// How many updates a bounce cell serves (ProbeFrame::bounce.y): one while the field builds up
// its bounces (its first vigilant frames, a light switch's vigilance), half the setting while the
// lights drift, the whole setting when they hold still.
TEST(ProbeFieldFrame, BounceCellsServeLongestWhileTheLightsHoldStill) {
  ProbeFieldSettings s;
  s.vigilantFrames = 2;
  s.bounceCellUpdates = 16;
  ProbeFieldFrameBuilder builder(s);
  const CascadeStackImage image = oneCascade();
  ProbeFrameInputs in;
  EXPECT_EQ(builder.build(image, in, 0).constants.bounce.y, 1u);
  EXPECT_EQ(builder.build(image, in, 1).constants.bounce.y, 1u);
  EXPECT_EQ(builder.build(image, in, 2).constants.bounce.y, 16u);
  in.lightsDrifting = true;
  EXPECT_EQ(builder.build(image, in, 3).constants.bounce.y, 8u);
  in.lightsDrifting = false;
  in.lightsChanged = true;
  in.lightSwitchVigilantUpdates = 2;
  EXPECT_EQ(builder.build(image, in, 4).constants.bounce.y, 1u);
  in.lightsChanged = false;
  EXPECT_EQ(builder.build(image, in, 5).constants.bounce.y, 1u);
  EXPECT_EQ(builder.build(image, in, 6).constants.bounce.y, 16u);
  // Off stays off (no cells are allocated): every hit looks the probes up itself, drifting too.
  s.bounceCellUpdates = 0;
  ProbeFieldFrameBuilder perHit(s);
  in.lightsDrifting = true;
  for (std::uint64_t frame = 0; frame < 4; ++frame)
    EXPECT_EQ(perHit.build(image, in, frame).constants.bounce.y, 0u) << "frame " << frame;
}

}  // namespace
}  // namespace sdfstream::probe
