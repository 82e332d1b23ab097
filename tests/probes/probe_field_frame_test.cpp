// ProbeFieldFrameBuilder: what a frame's constants say about the light switch -- the hit-cache
// rotation a second update of the same frame takes, the catch-up's hysteresis and the vigilance
// counts the classify and blend passes read (shaders/probe_field.glsl,
// probeVigilantHysteresis).
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

TEST(ProbeFieldFrame, ARotationShiftTakesAnotherRotationOfTheCycle) {
  ProbeFieldSettings s;  // hit cache on: 4 rotations cycled by frame
  ProbeFieldFrameBuilder builder(s);
  const CascadeStackImage image = oneCascade();
  ProbeFrameInputs in;
  const ProbeFieldFrame first = builder.build(image, in, 5);
  in.rotationShift = 2;
  const ProbeFieldFrame second = builder.build(image, in, 5);
  EXPECT_EQ(first.volumes[0].rayRotationCol0.w, 1.0f);   // 5 % 4
  EXPECT_EQ(second.volumes[0].rayRotationCol0.w, 3.0f);  // (5 + 2) % 4
  EXPECT_NE(first.volumes[0].rayRotationCol0, second.volumes[0].rayRotationCol0);
  // The slot's rotation is the one the cache's table holds for it, and the select pass's share
  // of an overflowing class moves on with the shift too (other probes where not all fit).
  EXPECT_EQ(glm::vec3(second.volumes[0].rayRotationCol0), glm::vec3(second.rayPattern[3 * 3]));
  EXPECT_EQ(first.constants.options.y, 5u);
  EXPECT_EQ(second.constants.options.y, 7u);
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
