// GiSettings::lightSwitchCatchUpFrames: after a light switch the frame runs
// lightSwitchUpdatesPerFrame probe updates (one more bounce of the new light each) for that many
// frames; the first frame, a drifting sun and a paused field run one.
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>

#include "gi/gi_system.h"
#include "gpu/context.h"
#include "tests/support/streamed_bunny.h"

namespace sdfstream::test {
namespace {

int probeUpdatesIn(const GiFrameStats& s) {
  return int(std::count_if(s.passes.begin(), s.passes.end(),
                           [](const gpu::PassTiming& p) { return p.name == "probe_trace"; }));
}

TEST(GiLightSwitch, ASwitchRunsCatchUpUpdatesForItsFrames) {
  StreamedBunny bunny = streamBunny("gi-light-switch-bunny");
  auto context = gpu::Context::create(gpu::ContextOptions{});
  GiSettings settings;
  settings.probes.spacingBricks = 4;
  settings.probes.raysPerProbe = 32;
  settings.lightSwitchCatchUpFrames = 3;
  settings.lightSwitchUpdatesPerFrame = 2;
  GiSystem gi(*context, settings, 3);
  SceneLights lights = bunnySunAndSky();
  probe::ProbeFrameInputs inputs;
  inputs.cameraWorld = bunny.camera;
  bunny.stack->update(bunny.camera);
  std::vector<std::uint32_t> dirty = bunny.stack->takeDirtySlots();
  std::uint64_t frame = 0;
  auto run = [&] {
    const GiFrameStats s = gi.update(*bunny.stack, dirty, lights, inputs, frame++);
    dirty.clear();
    return probeUpdatesIn(s);
  };
  // The first frame's lights catch up as a switch does: a new field builds its bounces too.
  for (int i = 0; i < 3; ++i) EXPECT_EQ(run(), 2) << "frame " << frame - 1;
  for (int i = 0; i < 2; ++i) EXPECT_EQ(run(), 1) << "frame " << frame - 1;

  // Switched off: three frames of two updates, then one.
  SceneLights off = lights;
  off.lights.clear();
  off.version = lights.version + 1;
  std::swap(lights, off);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(run(), 2) << "frame " << frame - 1;
  for (int i = 0; i < 2; ++i) EXPECT_EQ(run(), 1) << "frame " << frame - 1;

  // On again while paused: the catch-up waits for the field to run.
  std::swap(lights, off);
  lights.version = off.version + 1;
  inputs.paused = true;
  EXPECT_EQ(run(), 0);
  inputs.paused = false;
  for (int i = 0; i < 3; ++i) EXPECT_EQ(run(), 2) << "frame " << frame - 1;
  EXPECT_EQ(run(), 1);

  // A sun turning half a degree drifts: no catch-up.
  const glm::mat3 turn(glm::rotate(glm::mat4(1.0f), glm::radians(0.5f), glm::vec3(0, 1, 0)));
  lights.lights[0].direction = turn * lights.lights[0].direction;
  ++lights.version;
  EXPECT_EQ(run(), 1);
}

}  // namespace
}  // namespace sdfstream::test
