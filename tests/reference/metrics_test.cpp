// relMSE and the tone map (reference/metrics.h).
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "reference/metrics.h"

namespace sdfstream::reference {
namespace {

std::vector<glm::vec3> ramp(std::size_t n) {
  std::vector<glm::vec3> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float t = float(i) / float(n);
    v[i] = glm::vec3(0.1f + t, 2.0f * t, 5.0f - 3.0f * t);
  }
  return v;
}

TEST(RelMse, ZeroForIdenticalInputs) {
  const auto x = ramp(2000);
  EXPECT_EQ(relMSE(x, x), 0.0);
  EXPECT_EQ(relMSE(std::vector<glm::vec3>{}, std::vector<glm::vec3>{}), 0.0);
}

TEST(RelMse, KnownPerturbation) {
  // Reference 1 everywhere, test 1.1: each channel (0.1)² / (1² + 0.01) = 0.01 / 1.01.
  const std::vector<glm::vec3> ref(500, glm::vec3(1.0f)), test(500, glm::vec3(1.1f));
  const double d = double(1.1f) - 1.0;
  EXPECT_NEAR(relMSE(test, ref), d * d / 1.01, 1e-9);
  // Relative: scaling both by 10 changes only the ε term: 1 / (100 + 0.01).
  const std::vector<glm::vec3> ref10(500, glm::vec3(10.0f)), test10(500, glm::vec3(11.0f));
  EXPECT_NEAR(relMSE(test10, ref10), 1.0 / 100.01, 1e-9);
  // One channel off by 100% (ref 2, test 0): (4 / 4.01) / 3 per point.
  const std::vector<glm::vec3> ref2(10, glm::vec3(2.0f, 1.0f, 1.0f)),
      test2(10, glm::vec3(0.0f, 1.0f, 1.0f));
  EXPECT_NEAR(relMSE(test2, ref2), 4.0 / 4.01 / 3.0, 1e-9);
}

TEST(RelMse, TopTenthPercentDiscardRemovesOneOutlier) {
  const auto ref = ramp(1000);
  auto test = ref;
  test[417] = glm::vec3(1e6f);             // a firefly
  EXPECT_EQ(relMSE(test, ref), 0.0);       // 1 of 1,000 discarded
  EXPECT_GT(relMSE(test, ref, 0.0), 1e6);  // not discarded: dominates
  // With 999 points floor(0.999) = 0 are discarded: the firefly counts.
  const std::vector<glm::vec3> ref999(ref.begin(), ref.begin() + 999),
      test999(test.begin(), test.begin() + 999);
  EXPECT_GT(relMSE(test999, ref999), 1e6);
  // A NaN is the worst error: discarded first.
  test[417] = glm::vec3(std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(relMSE(test, ref), 0.0);
  EXPECT_TRUE(std::isinf(relMSE(test, ref, 0.0)));
}

TEST(RelMse, RejectsMismatchedInput) {
  const auto a = ramp(10), b = ramp(11);
  EXPECT_THROW(relMSE(a, b), std::invalid_argument);
  EXPECT_THROW(relMSE(a, a, 1.0), std::invalid_argument);
}

TEST(ToneMap, AcesIsMonotonicAndBounded) {
  EXPECT_EQ(toneMapAces(glm::vec3(0.0f)), glm::vec3(0.0f));
  EXPECT_EQ(toneMapAces(glm::vec3(-1.0f)), glm::vec3(0.0f));
  // Strictly increasing until the curve reaches 1 (near x = 10; its asymptote 2.51/2.43 is above 1,
  // hence the clamp), then exactly 1.
  float previous = 0.0f;
  for (float x = 0.01f; x < 8.0f; x *= 1.5f) {
    const float y = toneMapAces(glm::vec3(x)).x;
    EXPECT_GT(y, previous);
    EXPECT_LT(y, 1.0f);
    previous = y;
  }
  EXPECT_GT(previous, 0.98f);
  EXPECT_EQ(toneMapAces(glm::vec3(20.0f)).x, 1.0f);
  EXPECT_EQ(toneMapAces(glm::vec3(1e30f)).x, 1.0f);
  EXPECT_EQ(toneMapAces(glm::vec3(std::numeric_limits<float>::infinity())).x, 1.0f);
  EXPECT_EQ(toneMapAces(glm::vec3(std::numeric_limits<float>::quiet_NaN())).x, 0.0f);
  // Narkowicz's curve at 1: (2.51 + 0.03) / (2.43 + 0.59 + 0.14).
  EXPECT_NEAR(toneMapAces(glm::vec3(1.0f)).x, 2.54f / 3.16f, 1e-6f);
  EXPECT_NEAR(toneMapAces(glm::vec3(0.5f), 2.0f).x, 2.54f / 3.16f, 1e-6f);
}

TEST(ToneMap, SrgbRoundTrip) {
  for (float v = 0.0f; v <= 1.0f; v += 0.01f) {
    EXPECT_NEAR(srgbToLinear(linearToSrgb(glm::vec3(v))).x, v, 1e-5f);
  }
  EXPECT_NEAR(linearToSrgb(glm::vec3(0.18f)).x, 0.4613f, 1e-3f);  // mid grey encodes to ~118/255
}

}  // namespace
}  // namespace sdfstream::reference
