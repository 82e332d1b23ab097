// A gtest fixture for any module's GPU tests: each test gets a fresh Context with Vulkan
// validation on, and fails if the validation layer reported anything -- during the test or while
// the Context was torn down (leaked objects are reported then).
//
//   #include "tests/support/gpu_test.h"
//   class TraceTest : public sdfstream::test::GpuTest {};
//   TEST_F(TraceTest, Hits) { sdfstream::gpu::Buffer b(ctx(), 64, ...); ... }
//
// The device is the automatic choice, or $SDFSTREAM_DEVICE. Link sdfstream_gpu.
#pragma once

#include <cstdint>
#include <memory>

#include <gtest/gtest.h>

#include "gpu/context.h"

namespace sdfstream::test {

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    messagesBefore_ = gpu::Context::processValidationMessageCount();
    gpu::ContextOptions options;
    options.validation = true;
    context_ = gpu::Context::create(options);
  }

  void TearDown() override {
    if (context_) {
      context_->waitIdle();
      EXPECT_EQ(context_->pendingDeletionCount(), 0u);
    }
    context_.reset();
    EXPECT_EQ(gpu::Context::processValidationMessageCount() - messagesBefore_, 0u)
        << "Vulkan validation reported problems (printed above as [vulkan error/warning])";
  }

  gpu::Context& ctx() { return *context_; }

 private:
  std::unique_ptr<gpu::Context> context_;
  std::uint64_t messagesBefore_ = 0;
};

}  // namespace sdfstream::test
