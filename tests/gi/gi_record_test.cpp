// Record mode (GiSystem::record into an engine's command buffer on an adopted device) against
// the blocking mode (GiSystem::update on a Context of its own): the same 100 streamed frames with
// moving objects give bit-identical GPU results, the engine submits exactly once per frame, and
// sdfstream neither submits nor waits on the GPU inside the frame loop.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>

#include <glm/gtc/quaternion.hpp>

#include "gi/gi_system.h"
#include "objects/instance_set.h"
#include "objects/object_library.h"
#include "tests/support/engine_device.h"
#include "tests/support/streamed_bunny.h"

namespace sdfstream::test {
namespace {

constexpr int kFrames = 100;

GiSettings smallSettings() {
  GiSettings s;
  s.probes.spacingBricks = 4;  // 5³ probes per cascade: the test is about the frame, not the GI
  s.probes.raysPerProbe = 32;
  s.framesInFlight = 2;
  // Cards captured in setObjects, before the frames: none of the frames submits.
  s.objects.cardTexelWorld = 0.01;
  return s;
}

// Three objects orbiting the bunny, the same poses in both runs.
struct Orbiters {
  InstanceSet instances;
  std::vector<InstanceId> ids;
  Orbiters(std::uint32_t box, std::uint32_t sphere) {
    for (int i = 0; i < 3; ++i) ids.push_back(instances.add(i % 2 ? box : sphere, pose(i, 0)));
  }
  static ObjectTransform pose(int i, int frame) {
    const double a = 0.7 * i + 0.05 * frame;
    ObjectTransform t;
    t.translation = glm::dvec3(0.3 + 0.45 * std::cos(a), 0.25 + 0.1 * i, 0.2 + 0.45 * std::sin(a));
    t.rotation = glm::angleAxis(float(a), glm::vec3(0.0f, 1.0f, 0.0f));
    return t;
  }
  void step(int frame) {
    for (int i = 0; i < int(ids.size()); ++i) instances.move(ids[std::size_t(i)], pose(i, frame));
  }
};

template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

TEST(GiRecord, StreamedFramesWithObjectsMatchBlockingBitForBitWithoutWaits) {
  const std::uint64_t messagesBefore = gpu::Context::processValidationMessageCount();
  StreamedBunny bunny = streamBunny("gi-record-bunny");
  ObjectLibrary library(ObjectSdfSettings{16, 24, 0.0, 2});
  const std::uint32_t box = library.addBox({0.06f, 0.04f, 0.05f}, {0.8f, 0.2f, 0.2f, 1.0f});
  const std::uint32_t sphere = library.addSphere(0.05f, {0.2f, 0.7f, 0.3f, 1.0f}, 16);
  Orbiters blockingObjects(box, sphere), recordedObjects(box, sphere);

  gpu::ContextOptions options;
  options.validation = true;
  auto own = gpu::Context::create(options);
  auto engine = std::make_unique<EngineDevice>(2);
  auto adopted = gpu::Context::adopt(engine->adopted(), options);
  ASSERT_TRUE(adopted->adopted());
  ASSERT_TRUE(adopted->validationEnabled());

  const std::uint32_t cascades = 3;
  // Destroyed before the Contexts (and so before the engine's device), as every GPU object.
  auto blockingGi = std::make_unique<GiSystem>(*own, smallSettings(), cascades);
  auto recordedGi = std::make_unique<GiSystem>(*adopted, smallSettings(), cascades);
  GiSystem& blocking = *blockingGi;
  GiSystem& recorded = *recordedGi;
  blocking.setObjects(&library, &blockingObjects.instances);
  recorded.setObjects(&library, &recordedObjects.instances);
  SceneLights lights = bunnySunAndSky();

  const std::uint64_t submitsBefore = adopted->submitCount();
  const std::uint64_t waitsBefore = adopted->hostWaitCount();
  std::size_t streamedSlots = 0;
  int statsSeen = 0;
  std::optional<GiFrameStats> newestRecorded;  // completedStats() hands each frame out once
  GiFrameStats lastBlocking;
  std::uint64_t raysTracedBlocking = 0;  // over the whole flight: the comparison is not vacuous
  for (int f = 0; f < kFrames; ++f) {
    // The camera flies past the bunny: cascades scroll and new bricks stream in.
    const glm::dvec3 camera = bunny.camera + glm::dvec3(0.004 * f, 0.0, -0.003 * f);
    bunny.stack->update(camera);
    const std::vector<std::uint32_t> dirty = bunny.stack->takeDirtySlots();
    streamedSlots += dirty.size();
    blockingObjects.step(f);
    recordedObjects.step(f);
    probe::ProbeFrameInputs inputs;
    inputs.cameraWorld = camera;
    lastBlocking = blocking.update(*bunny.stack, dirty, lights, inputs, std::uint64_t(f));
    raysTracedBlocking += lastBlocking.probes.raysTraced;

    VkCommandBuffer cb = engine->beginFrame(std::uint64_t(f));
    const GiFrameRecording rec =
        recorded.record(cb, *bunny.stack, dirty, lights, inputs, std::uint64_t(f));
    engine->submitFrame(rec.signal);
    if (auto s = recorded.completedStats()) {
      ++statsSeen;
      // Only frames the GPU has finished; on a CPU device that may already be this one.
      EXPECT_LE(s->frame, std::uint64_t(f));
      newestRecorded = s;
    }
  }
  // Inside the loop: the engine's 100 submissions, none by sdfstream, no sdfstream wait.
  const std::uint64_t loopSubmits = adopted->submitCount() - submitsBefore;
  const std::uint64_t loopWaits = adopted->hostWaitCount() - waitsBefore;
  EXPECT_EQ(engine->submissions, std::uint64_t(kFrames));
  EXPECT_EQ(loopSubmits, 0u);
  EXPECT_EQ(loopWaits, 0u);
  EXPECT_GT(streamedSlots, 0u) << "the camera path must stream bricks";
  EXPECT_GT(statsSeen, 0);

  vkDeviceWaitIdle(engine->device);  // the engine's own wait, after its frame loop
  // The last frame's statistics: here, or already taken in the loop's last call when the
  // device had finished it by then (a CPU device often has).
  if (auto s = recorded.completedStats()) newestRecorded = s;
  const auto stats = newestRecorded;
  ASSERT_TRUE(stats.has_value());
  EXPECT_EQ(stats->frame, std::uint64_t(kFrames - 1));
  EXPECT_EQ(stats->probes.raysTraced, lastBlocking.probes.raysTraced);
  EXPECT_EQ(stats->probes.raysCached, lastBlocking.probes.raysCached);
  EXPECT_EQ(stats->pagesRelit, lastBlocking.pagesRelit);
  // The last frame shades rays (fresh or from the hit cache, as the states and the cache decide)
  // and the flight traced fresh ones.
  EXPECT_GT(lastBlocking.probes.raysTraced + lastBlocking.probes.raysCached, 0u);
  EXPECT_GT(raysTracedBlocking, 0u);

  const auto irradianceA = blocking.probes().downloadIrradiance();
  EXPECT_TRUE(sameBits(irradianceA, recorded.probes().downloadIrradiance()));
  EXPECT_TRUE(sameBits(blocking.probes().downloadDepth(), recorded.probes().downloadDepth()));
  EXPECT_TRUE(
      sameBits(blocking.probes().downloadProbeData(), recorded.probes().downloadProbeData()));
  EXPECT_TRUE(
      sameBits(blocking.lightCache().downloadRadiance(), recorded.lightCache().downloadRadiance()));
  double sum = 0.0;
  for (const glm::vec4& t : irradianceA) sum += t.x + t.y + t.z;
  EXPECT_GT(sum, 0.0) << "a lit scene: the comparison must not be between two black fields";
  std::printf(
      "[figures] record vs blocking: %d frames, %zu streamed slots, engine submits %llu, "
      "sdfstream submits %llu, sdfstream waits %llu, irradiance texels %zu bit-equal\n",
      kFrames, streamedSlots, static_cast<unsigned long long>(engine->submissions),
      static_cast<unsigned long long>(loopSubmits), static_cast<unsigned long long>(loopWaits),
      irradianceA.size());

  recordedGi.reset();
  blockingGi.reset();
  adopted.reset();  // before the engine destroys its device
  engine.reset();
  own.reset();
  EXPECT_EQ(gpu::Context::processValidationMessageCount() - messagesBefore, 0u);
}

TEST(GiRecord, AdoptNamesWhatTheEnginesDeviceLacks) {
  EngineDevice engine(1, /*withExtensions=*/false);
  try {
    gpu::Context::adopt(engine.adopted());
    FAIL() << "adopt must refuse a device without VK_KHR_push_descriptor";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("VK_KHR_push_descriptor (supported but not enabled)"),
              std::string::npos)
        << e.what();
  }
  gpu::AdoptedDevice noTimeline = engine.adopted();
  noTimeline.enabledVulkan12Features.timelineSemaphore = VK_FALSE;
  try {
    gpu::Context::adopt(noTimeline);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("timelineSemaphore"), std::string::npos) << e.what();
  }
}

TEST(GiRecord, AdoptedContextLeavesTheEnginesDeviceAlive) {
  EngineDevice engine(1);
  {
    auto ctx = gpu::Context::adopt(engine.adopted());
    gpu::Buffer b(*ctx, 256, gpu::BufferKind::DeviceLocal);
    gpu::CommandBatch batch = ctx->beginBatch();
    batch.fill(b, 7u);
    batch.submitAndWait();
    EXPECT_EQ(ctx->submitCount(), 1u);
    EXPECT_EQ(ctx->hostWaitCount(), 1u);
  }
  // The engine's device still works: a submission of its own completes.
  VkCommandBuffer cb = engine.beginFrame(0);
  vkEndCommandBuffer(cb);
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  EXPECT_EQ(vkQueueSubmit(engine.queue, 1, &submit, engine.fences[0]), VK_SUCCESS);
  EXPECT_EQ(vkWaitForFences(engine.device, 1, &engine.fences[0], VK_TRUE, UINT64_MAX), VK_SUCCESS);
}

}  // namespace
}  // namespace sdfstream::test
