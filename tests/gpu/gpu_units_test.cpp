// Device-free tests of the gpu module's rules: device choice, memory types, deferred-destruction
// bookkeeping, SPIR-V reflection and the embedded shader table.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "gpu/deletion_queue.h"
#include "gpu/device_select.h"
#include "gpu/memory_type.h"
#include "gpu/spirv_info.h"
#include "shaders/embedded_shaders.h"

namespace sdfstream::gpu {
namespace {

TEST(DeviceSelect, AutoPrefersDiscreteThenIntegratedAndSkipsUnsuitable) {
  std::vector<DeviceCandidate> c = {
      {"llvmpipe (LLVM 15)", VK_PHYSICAL_DEVICE_TYPE_CPU, ""},
      {"Intel UHD 630", VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU, ""},
      {"Old Radeon", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, "needs Vulkan 1.2"},
      {"NVIDIA RTX 4090", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, ""},
  };
  EXPECT_EQ(selectDevice(c, ""), 3u);
  c.pop_back();
  EXPECT_EQ(selectDevice(c, ""), 1u);
  c.erase(c.begin() + 1);
  EXPECT_EQ(selectDevice(c, ""), 0u);
}

TEST(DeviceSelect, ByIndexOrCaseInsensitiveSubstring) {
  std::vector<DeviceCandidate> c = {{"llvmpipe (LLVM 15)", VK_PHYSICAL_DEVICE_TYPE_CPU, ""},
                                    {"NVIDIA RTX 4090", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, ""}};
  EXPECT_EQ(selectDevice(c, "0"), 0u);
  EXPECT_EQ(selectDevice(c, "1"), 1u);
  EXPECT_EQ(selectDevice(c, "rtx"), 1u);
  EXPECT_EQ(selectDevice(c, "LLVMPIPE"), 0u);
}

TEST(DeviceSelect, NoMatchIsOneLineListingDevices) {
  std::vector<DeviceCandidate> c = {{"llvmpipe (LLVM 15)", VK_PHYSICAL_DEVICE_TYPE_CPU, ""}};
  try {
    selectDevice(c, "foo");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("no Vulkan device matches --device 'foo'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("available: 0: llvmpipe (LLVM 15) [cpu]"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
  EXPECT_THROW(selectDevice(c, "7"), std::runtime_error);
  c[0].unsuitableReason = "lacks VK_KHR_push_descriptor";
  EXPECT_THROW(selectDevice(c, ""), std::runtime_error);
  EXPECT_THROW(selectDevice(c, "llvm"), std::runtime_error);
}

TEST(MemoryType, HonoursRequiredPreferredAvoidedAndTypeBits) {
  VkPhysicalDeviceMemoryProperties p{};
  p.memoryTypeCount = 3;
  p.memoryTypes[0].propertyFlags = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  p.memoryTypes[1].propertyFlags =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  p.memoryTypes[2].propertyFlags = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                   VK_MEMORY_PROPERTY_HOST_COHERENT_BIT |
                                   VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  const VkMemoryPropertyFlags host =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  EXPECT_EQ(findMemoryType(p, 0b111, {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0, 0}), 0u);
  EXPECT_EQ(findMemoryType(p, 0b111, {host, VK_MEMORY_PROPERTY_HOST_CACHED_BIT, 0}), 2u);
  EXPECT_EQ(findMemoryType(p, 0b111, {host, 0, VK_MEMORY_PROPERTY_HOST_CACHED_BIT}), 1u);
  EXPECT_EQ(findMemoryType(p, 0b011, {host, VK_MEMORY_PROPERTY_HOST_CACHED_BIT, 0}), 1u);
  EXPECT_EQ(findMemoryType(p, 0b001, {host, 0, 0}), std::nullopt);
}

TEST(DeletionQueue, RunsInOrderOnlyWhenSubmissionCompleted) {
  DeletionQueue q;
  std::vector<int> ran;
  q.push(1, [&] { ran.push_back(1); });
  q.push(2, [&] { ran.push_back(2); });
  q.push(2, [&] { ran.push_back(3); });
  EXPECT_EQ(q.collect(0), 0u);
  EXPECT_EQ(q.collect(1), 1u);
  EXPECT_EQ(q.size(), 2u);
  EXPECT_EQ(q.collect(5), 2u);
  EXPECT_EQ(ran, (std::vector<int>{1, 2, 3}));
  q.push(9, [&] { ran.push_back(4); });
  q.runAll();
  EXPECT_EQ(ran.size(), 4u);
}

TEST(EmbeddedShaders, TableIsValidSpirvNamedByFileStem) {
  ASSERT_GE(kShaderCount, 1u);
  for (std::size_t i = 0; i < kShaderCount; ++i) {
    auto id = static_cast<ShaderId>(i);
    auto words = shaderSpirv(id);
    ASSERT_GT(words.size(), 5u) << shaderName(id);
    EXPECT_EQ(words[0], 0x07230203u) << shaderName(id);
  }
  EXPECT_STREQ(shaderName(ShaderId::selftest_saxpy), "selftest_saxpy");
}

TEST(SpirvInfo, ReadsLocalSizeAndRejectsGarbage) {
  EXPECT_EQ(spirvLocalSize(shaderSpirv(ShaderId::selftest_saxpy)), glm::uvec3(64, 1, 1));
  std::vector<std::uint32_t> junk = {0x07230203u, 0, 0, 0, 0, 0xffff0010u};
  EXPECT_EQ(spirvLocalSize(junk), std::nullopt);
  EXPECT_EQ(spirvLocalSize({}), std::nullopt);
}

}  // namespace
}  // namespace sdfstream::gpu
