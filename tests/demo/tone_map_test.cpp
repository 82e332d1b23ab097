// The tone map of the demo frames (demo/frame_image.h): ACES fitted keeps black black, is
// monotonic, saturates towards white, and never lets NaN/Inf through.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "demo/frame_image.h"

namespace sdfstream {
namespace {

TEST(ToneMap, AcesFittedIsMonotonicFromBlackToWhite) {
  EXPECT_EQ(acesFitted(glm::vec3(0.0f)), glm::vec3(0.0f));
  float previous = 0.0f;
  for (float x = 0.001f; x < 1000.0f; x *= 1.1f) {
    const float y = acesFitted(glm::vec3(x)).g;
    EXPECT_GE(y, previous) << x;
    previous = y;
  }
  EXPECT_GT(acesFitted(glm::vec3(100.0f)).r, 0.99f);
  // Mid grey lands in the middle of the output range (Hill's fit: 0.18 -> about 0.1 linear).
  EXPECT_NEAR(acesFitted(glm::vec3(0.18f)).g, 0.1f, 0.03f);
}

TEST(ToneMap, NonFiniteRadianceBecomesBlackAndIsCounted) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<glm::vec3> radiance = {glm::vec3(nan, 0.5f, 0.5f), glm::vec3(inf), glm::vec3(-1.0f),
                                     glm::vec3(0.5f)};
  std::size_t bad = 0;
  const Image8 img = toneMap(radiance, 2, 2, 0.0f, &bad);
  EXPECT_EQ(bad, 2u);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(img.rgb[i], 0) << i;  // NaN, Inf, negative
  EXPECT_GT(img.rgb[9], 100);
  // One stop more doubles the input.
  const Image8 brighter = toneMap(radiance, 2, 2, 1.0f);
  EXPECT_GT(brighter.rgb[9], img.rgb[9]);
}

// addedLight keeps only what the first image adds, scaled and clamped, channel by channel.
TEST(AddedLight, KeepsWhatTheFirstImageAddsScaledAndClamped) {
  const Image8 with{2, 1, {10, 200, 50, 100, 0, 255}};
  const Image8 without{2, 1, {5, 210, 50, 20, 0, 0}};
  const Image8 added = addedLight(with, without, 4.0f);
  EXPECT_EQ(added.width, 2);
  EXPECT_EQ(added.height, 1);
  EXPECT_EQ(added.rgb, (std::vector<std::uint8_t>{20, 0, 0, 255, 0, 255}));
  EXPECT_THROW(addedLight(with, Image8{1, 1, {0, 0, 0}}, 1.0f), std::invalid_argument);
}

}  // namespace
}  // namespace sdfstream
