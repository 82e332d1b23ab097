// Dispatch helper: a real kernel against its CPU reference, and named non-negative timings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "tests/gpu/saxpy.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::test {
namespace {

using gpu::Buffer;
using gpu::BufferKind;

class CommandBatchTest : public GpuTest {};

TEST_F(CommandBatchTest, SaxpyMatchesCpuExactly) {
  constexpr std::uint32_t n = 100000;  // not a multiple of 64: exercises the partial group
  const float a = 2.5f;
  const std::vector<float> x = randomFloats(n, 1), y = randomFloats(n, 2);
  Buffer bx(ctx(), n * sizeof(float), BufferKind::DeviceLocal);
  Buffer by(ctx(), n * sizeof(float), BufferKind::DeviceLocal);
  bx.upload(x.data(), n * sizeof(float));
  by.upload(y.data(), n * sizeof(float));
  gpu::ComputePipeline saxpy = makeSaxpy(ctx());

  gpu::CommandBatch batch = ctx().beginBatch();
  SaxpyPush push{a, n};
  batch.dispatch("saxpy", saxpy, {&bx, &by}, &push, sizeof push, {n, 1, 1});
  batch.submitAndWait();

  std::vector<float> result(n);
  by.download(result.data(), n * sizeof(float));
  std::size_t mismatches = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const float expected = saxpyReference(a, x[i], y[i]);
    if (std::memcmp(&expected, &result[i], sizeof(float)) != 0 && mismatches++ < 5)
      ADD_FAILURE() << "element " << i << ": gpu " << result[i] << " cpu " << expected;
  }
  EXPECT_EQ(mismatches, 0u);
}

// Specialization constant 0 picks the code: each variant of a pair computes its own result, and
// asking again returns the pipeline made the first time.
TEST_F(CommandBatchTest, PipelinePairVariantsFollowTheirConstant) {
  constexpr std::uint32_t n = 1000;
  const float a = 1.5f;
  const std::vector<float> x = randomFloats(n, 3), y = randomFloats(n, 4);
  gpu::ComputePipelinePair pair(ctx(), gpu::ShaderId::selftest_saxpy, saxpyDesc());
  for (const bool subtract : {false, true, false}) {
    Buffer bx(ctx(), n * sizeof(float), BufferKind::DeviceLocal);
    Buffer by(ctx(), n * sizeof(float), BufferKind::DeviceLocal);
    bx.upload(x.data(), n * sizeof(float));
    by.upload(y.data(), n * sizeof(float));
    const VkPipeline first = pair.get(subtract).handle();
    gpu::CommandBatch batch = ctx().beginBatch();
    SaxpyPush push{a, n};
    batch.dispatch("saxpy", pair.get(subtract), {&bx, &by}, &push, sizeof push, {n, 1, 1});
    batch.submitAndWait();
    EXPECT_EQ(pair.get(subtract).handle(), first);
    EXPECT_NE(pair.get(!subtract).handle(), first);
    std::vector<float> result(n);
    by.download(result.data(), n * sizeof(float));
    std::size_t mismatches = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const float ax = a * x[i];
      const float expected = subtract ? y[i] - ax : ax + y[i];
      if (std::memcmp(&expected, &result[i], sizeof(float)) != 0 && mismatches++ < 5)
        ADD_FAILURE() << "subtract " << subtract << ", element " << i << ": gpu " << result[i]
                      << " cpu " << expected;
    }
    EXPECT_EQ(mismatches, 0u) << "subtract " << subtract;
  }
}

TEST_F(CommandBatchTest, ChainedPassesSeeEachOthersWritesAndAreTimed) {
  constexpr std::uint32_t n = 4096;
  const std::vector<float> x = randomFloats(n, 3);
  Buffer bx(ctx(), n * sizeof(float), BufferKind::Upload);
  Buffer by(ctx(), n * sizeof(float), BufferKind::DeviceLocal);
  Buffer out(ctx(), n * sizeof(float), BufferKind::Readback);
  bx.upload(x.data(), n * sizeof(float));
  gpu::ComputePipeline saxpy = makeSaxpy(ctx());

  gpu::CommandBatch batch = ctx().beginBatch();
  batch.fill(by, 0);  // y = 0
  SaxpyPush first{1.0f, n}, second{2.0f, n};
  batch.dispatch("first", saxpy, {&bx, &by}, &first, sizeof first, {n, 1, 1});     // y = x
  batch.dispatch("second", saxpy, {&bx, &by}, &second, sizeof second, {n, 1, 1});  // y = 3x
  batch.copy(by, out, n * sizeof(float));
  batch.submitAndWait();

  std::vector<float> result(n);
  out.download(result.data(), n * sizeof(float));
  for (std::uint32_t i = 0; i < n; ++i)
    ASSERT_EQ(result[i], saxpyReference(2.0f, x[i], saxpyReference(1.0f, x[i], 0.0f))) << i;

  const std::vector<gpu::PassTiming> timings = batch.timings();
  ASSERT_EQ(timings.size(), 2u);
  EXPECT_EQ(timings[0].name, "first");
  EXPECT_EQ(timings[1].name, "second");
  for (const auto& t : timings) {
    EXPECT_TRUE(std::isfinite(t.milliseconds)) << t.name;
    EXPECT_GE(t.milliseconds, 0.0) << t.name;
    EXPECT_LT(t.milliseconds, 10000.0) << t.name;  // sane units: ms, not ticks or ns
  }
}

TEST_F(CommandBatchTest, EmptyDispatchAndEmptyBatchAreValid) {
  Buffer bx(ctx(), 0, BufferKind::DeviceLocal), by(ctx(), 0, BufferKind::DeviceLocal);
  gpu::ComputePipeline saxpy = makeSaxpy(ctx());
  gpu::CommandBatch batch = ctx().beginBatch();
  SaxpyPush push{1.0f, 0};
  batch.dispatch("nothing", saxpy, {&bx, &by}, &push, sizeof push, {0, 1, 1});
  batch.submitAndWait();
  EXPECT_EQ(batch.timings().size(), 1u);
  ctx().beginBatch().submitAndWait();
}

}  // namespace
}  // namespace sdfstream::test
