// STYLE.md habit 5: an owner destroyed while a submitted batch may still use its object must not
// free it until that batch has finished.
#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "tests/gpu/saxpy.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::test {
namespace {

using gpu::Buffer;
using gpu::BufferKind;

class DeferredDestructionTest : public GpuTest {};

TEST_F(DeferredDestructionTest, BufferAndPipelineUsedInFlightAreFreedAfterWait) {
  // Big enough that the batch is likely still running when the owners go away (not asserted:
  // a fast GPU may finish first, which must be just as correct).
  constexpr std::uint32_t n = 4'000'000;  // 62,500 groups: within the 65,535 limit
  std::optional<Buffer> x(std::in_place, ctx(), n * sizeof(float), BufferKind::DeviceLocal);
  std::optional<Buffer> y(std::in_place, ctx(), n * sizeof(float), BufferKind::DeviceLocal);
  std::optional<gpu::ComputePipeline> saxpy(makeSaxpy(ctx()));
  ctx().waitIdle();
  ASSERT_EQ(ctx().pendingDeletionCount(), 0u);

  gpu::CommandBatch batch = ctx().beginBatch();
  batch.fill(*x, 0x3f800000u);  // 1.0f
  batch.fill(*y, 0);
  SaxpyPush push{2.0f, n};
  for (int i = 0; i < 4; ++i)
    batch.dispatch("saxpy", *saxpy, {&*x, &*y}, &push, sizeof push, {n, 1, 1});
  const std::uint64_t submission = batch.submit();

  x.reset();
  y.reset();
  saxpy.reset();
  // Nothing is freed at destruction time, whatever the GPU's progress.
  EXPECT_EQ(ctx().pendingDeletionCount(), 3u);

  batch.wait();
  EXPECT_GE(ctx().completedSubmission(), submission);
  EXPECT_EQ(ctx().pendingDeletionCount(), 0u);  // wait() collects what became free
}

TEST_F(DeferredDestructionTest, ObjectsDestroyedBeforeAnySubmissionWaitForCollection) {
  { Buffer b(ctx(), 64, BufferKind::Upload); }
  EXPECT_EQ(ctx().pendingDeletionCount(), 1u);
  ctx().collectGarbage();
  EXPECT_EQ(ctx().pendingDeletionCount(), 0u);
}

TEST_F(DeferredDestructionTest, UnsubmittedBatchIsReleased) {
  Buffer b(ctx(), 64, BufferKind::DeviceLocal);
  {
    gpu::CommandBatch batch = ctx().beginBatch();
    batch.fill(b, 1);
  }
  EXPECT_EQ(ctx().pendingDeletionCount(), 1u);
  ctx().waitIdle();
  EXPECT_EQ(ctx().pendingDeletionCount(), 0u);
}

}  // namespace
}  // namespace sdfstream::test
