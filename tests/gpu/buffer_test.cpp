#include <gtest/gtest.h>

#include <numeric>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::test {
namespace {

using gpu::Buffer;
using gpu::BufferKind;

class BufferTest : public GpuTest {};

std::vector<std::uint32_t> pattern(std::size_t words, std::uint32_t salt) {
  std::vector<std::uint32_t> v(words);
  for (std::size_t i = 0; i < words; ++i) v[i] = std::uint32_t(i * 2654435761u) ^ salt;
  return v;
}

TEST_F(BufferTest, DeviceLocalRoundTripWholeAndAtOffset) {
  constexpr std::size_t words = 1 << 18;  // 1 MiB
  Buffer b(ctx(), words * 4, BufferKind::DeviceLocal);
  EXPECT_EQ(b.size(), words * 4);
  EXPECT_EQ(b.mapped(), nullptr);
  const auto data = pattern(words, 7);
  b.upload(data.data(), words * 4);

  const auto patch = pattern(100, 99);
  b.upload(patch.data(), 100 * 4, 1000 * 4);
  std::vector<std::uint32_t> back(words);
  b.download(back.data(), words * 4);
  auto expected = data;
  std::copy(patch.begin(), patch.end(), expected.begin() + 1000);
  EXPECT_EQ(back, expected);

  std::vector<std::uint32_t> part(10);
  b.download(part.data(), 10 * 4, 1000 * 4);
  EXPECT_TRUE(std::equal(part.begin(), part.end(), patch.begin()));
}

TEST_F(BufferTest, HostVisibleKindsRoundTrip) {
  for (BufferKind kind : {BufferKind::Upload, BufferKind::Readback}) {
    Buffer b(ctx(), 4096, kind);
    ASSERT_NE(b.mapped(), nullptr);
    const auto data = pattern(1024, 3);
    b.upload(data.data(), 4096);
    std::vector<std::uint32_t> back(1024);
    b.download(back.data(), 4096);
    EXPECT_EQ(back, data);
  }
}

TEST_F(BufferTest, SizesRoundUpToWordsAndZeroIsValid) {
  EXPECT_EQ(Buffer(ctx(), 0, BufferKind::DeviceLocal).size(), 4u);
  EXPECT_EQ(Buffer(ctx(), 5, BufferKind::Readback).size(), 8u);
  Buffer empty;
  EXPECT_FALSE(empty);
  Buffer moved = Buffer(ctx(), 16, BufferKind::Upload);
  empty = std::move(moved);
  EXPECT_TRUE(empty);
  EXPECT_FALSE(moved);  // NOLINT(bugprone-use-after-move): moved-from state is part of the contract
}

}  // namespace
}  // namespace sdfstream::test
