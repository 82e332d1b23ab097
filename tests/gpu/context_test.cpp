#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

#include "gpu/context.h"
#include "gpu/device_requirements.h"
#include "gpu/pipeline_statistics.h"
#include "tests/gpu/saxpy.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::test {
namespace {

class ContextTest : public GpuTest {};

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

// Restores an environment variable when the test ends.
class EnvGuard {
 public:
  explicit EnvGuard(const char* name) : name_(name) {
    if (const char* v = std::getenv(name)) old_ = v;
  }
  ~EnvGuard() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST_F(ContextTest, ReportsDeviceAndValidation) {
  EXPECT_FALSE(ctx().deviceName().empty());
  EXPECT_TRUE(ctx().validationEnabled());
  EXPECT_GT(ctx().timestampPeriodNs(), 0.0);
  EXPECT_NE(ctx().device(), VK_NULL_HANDLE);
  EXPECT_NE(ctx().queue(), VK_NULL_HANDLE);
  if (ctx().deviceName().find("llvmpipe") != std::string::npos) {
    EXPECT_TRUE(ctx().isSoftware());
  }
}

TEST_F(ContextTest, ChoosesDeviceByCaseInsensitiveSubstringOrIndex) {
  // A middle piece of the automatically chosen name, upper-cased.
  const std::string name = ctx().deviceName();
  const std::string piece = upper(name.substr(1, std::min<std::size_t>(6, name.size() - 1)));
  auto bySubstring = gpu::Context::create({.device = piece, .validation = true});
  EXPECT_EQ(bySubstring->deviceName(), name);
  auto byIndex = gpu::Context::create({.device = "0", .validation = true});
  EXPECT_FALSE(byIndex->deviceName().empty());
}

TEST_F(ContextTest, NonMatchingNameIsAClearOneLineError) {
  try {
    gpu::Context::create({.device = "no-such-gpu-xyz", .validation = true});
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("no Vulkan device matches --device 'no-such-gpu-xyz'"), std::string::npos)
        << msg;
    EXPECT_NE(msg.find("available: 0: " + ctx().deviceName()), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST_F(ContextTest, EnvironmentOverridesAutomaticChoiceOnly) {
  EnvGuard guard("SDFSTREAM_DEVICE");
  setenv("SDFSTREAM_DEVICE", "no-such-gpu-xyz", 1);
  try {
    gpu::Context::create({.device = "", .validation = true});
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("SDFSTREAM_DEVICE 'no-such-gpu-xyz'"), std::string::npos)
        << e.what();
  }
  // An explicit option wins over the environment.
  EXPECT_EQ(gpu::Context::create({.device = "0", .validation = true})->deviceName(),
            gpu::Context::create({.device = ctx().deviceName(), .validation = true})->deviceName());
}

// The resource report is opt-in and never a requirement: asked for on a device without the
// extension (lavapipe of Debian 12), the Context still works and says it captures nothing; on one
// with it, every pipeline reports at least one statistic of its executable.
TEST_F(ContextTest, PipelineStatisticsOnRequestWhereTheDeviceHasThem) {
  EnvGuard guard("SDFSTREAM_PIPELINE_STATS");
  EXPECT_FALSE(ctx().pipelineStatistics()) << "off unless asked for";
  setenv("SDFSTREAM_PIPELINE_STATS", "1", 1);
  auto asked = gpu::Context::create({.device = "0", .validation = true});
  EXPECT_EQ(asked->pipelineStatistics(),
            gpu::supportsExtension(asked->physicalDevice(), gpu::kPipelineStatisticsExtension));
  gpu::ComputePipeline saxpy = makeSaxpy(*asked);
  EXPECT_TRUE(bool(saxpy));
  if (asked->pipelineStatistics()) {
    const std::string line = gpu::pipelineStatisticsLine(asked->device(), saxpy.handle());
    EXPECT_NE(line.find('='), std::string::npos) << line;
  }
  EXPECT_EQ(asked->validationMessageCount(), 0u);
}

}  // namespace
}  // namespace sdfstream::test
