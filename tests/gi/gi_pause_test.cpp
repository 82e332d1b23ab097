// ProbeFrameInputs::paused (the viewer's GI-off): a paused frame records no probe pass, leaves the
// probe field bit for bit as it was while the light changes and the light cache relights, reports
// no probe work; the next unpaused frame updates the field again.
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "gi/gi_system.h"
#include "gpu/context.h"
#include "tests/support/streamed_bunny.h"

namespace sdfstream::test {
namespace {

template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

TEST(GiPause, PausedFramesKeepTheProbeFieldAndSkipItsPasses) {
  StreamedBunny bunny = streamBunny("gi-pause-bunny");
  auto context = gpu::Context::create(gpu::ContextOptions{});
  GiSettings settings;
  settings.probes.spacingBricks = 4;
  settings.probes.raysPerProbe = 32;
  GiSystem gi(*context, settings, 3);
  SceneLights lights = bunnySunAndSky();
  probe::ProbeFrameInputs inputs;
  inputs.cameraWorld = bunny.camera;
  bunny.stack->update(bunny.camera);
  std::vector<std::uint32_t> dirty = bunny.stack->takeDirtySlots();
  std::uint64_t frame = 0;
  for (; frame < 4; ++frame) {
    const GiFrameStats s = gi.update(*bunny.stack, dirty, lights, inputs, frame);
    dirty.clear();
    ASSERT_GT(s.probes.raysTraced + s.probes.raysCached, 0u);
  }
  const auto irradiance = gi.probes().downloadIrradiance();
  const auto radiance = gi.lightCache().downloadRadiance();

  // The sun doubles: the light cache relights, the paused field does not move.
  lights.lights[0].intensity = 6.0f;
  ++lights.version;
  inputs.paused = true;
  for (int i = 0; i < 2; ++i, ++frame) {
    const GiFrameStats s = gi.update(*bunny.stack, dirty, lights, inputs, frame);
    EXPECT_TRUE(s.probesPaused);
    EXPECT_EQ(s.probes.raysTraced, 0u);
    EXPECT_EQ(s.probes.probesUpdated, 0u);
    for (const gpu::PassTiming& p : s.passes)
      EXPECT_EQ(p.name.rfind("probe", 0), std::string::npos) << p.name << " ran while paused";
  }
  EXPECT_TRUE(sameBits(irradiance, gi.probes().downloadIrradiance()));
  EXPECT_FALSE(sameBits(radiance, gi.lightCache().downloadRadiance()));

  inputs.paused = false;
  const GiFrameStats resumed = gi.update(*bunny.stack, dirty, lights, inputs, frame);
  EXPECT_FALSE(resumed.probesPaused);
  EXPECT_GT(resumed.probes.raysTraced + resumed.probes.raysCached, 0u);
  EXPECT_FALSE(sameBits(irradiance, gi.probes().downloadIrradiance()));
}

}  // namespace
}  // namespace sdfstream::test
