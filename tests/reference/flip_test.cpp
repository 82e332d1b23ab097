// FLIP (reference/flip.h) against its defining properties and textbook CIELAB values.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "reference/metrics.h"

namespace sdfstream::reference {
namespace {

constexpr int kW = 48, kH = 40;

// A smooth colourful test image with an edge, so both pipelines have something to see.
std::vector<glm::vec3> testImage() {
  std::vector<glm::vec3> img(std::size_t(kW * kH));
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float u = float(x) / kW, v = float(y) / kH;
      glm::vec3 c(0.2f + 0.6f * u, 0.3f + 0.4f * v, 0.5f + 0.3f * std::sin(6.0f * u));
      if (x > 30) c *= 0.5f;
      img[std::size_t(y * kW + x)] = c;
    }
  return img;
}

// Fixed pseudo-random noise in [−1, 1] per pixel and channel.
float noise(std::uint32_t i) {
  i = (i ^ 61u) ^ (i >> 16);
  i *= 9u;
  i ^= i >> 4;
  i *= 0x27d4eb2du;
  i ^= i >> 15;
  return float(i & 0xffffu) / 32767.5f - 1.0f;
}

std::vector<glm::vec3> withNoise(const std::vector<glm::vec3>& img, float amplitude) {
  auto out = img;
  for (std::size_t i = 0; i < out.size(); ++i)
    for (int c = 0; c < 3; ++c)
      out[i][c] = std::clamp(out[i][c] + amplitude * noise(std::uint32_t(3 * i + c)), 0.0f, 1.0f);
  return out;
}

TEST(Flip, IdenticalImagesHaveZeroErrorEverywhere) {
  const auto img = testImage();
  const FlipResult r = flip(img, img, kW, kH);
  ASSERT_EQ(r.error.size(), img.size());
  for (float e : r.error) EXPECT_EQ(e, 0.0f);
  EXPECT_EQ(r.mean, 0.0);
}

TEST(Flip, BlackVersusWhiteIsNearlyMaximal) {
  const std::vector<glm::vec3> black(std::size_t(kW * kH), glm::vec3(0.0f)),
      white(std::size_t(kW * kH), glm::vec3(1.0f));
  const FlipResult r = flip(black, white, kW, kH);
  EXPECT_GT(r.mean, 0.9);
  EXPECT_LE(r.mean, 1.0);
}

// Uniform images: no features and no filtering effect, so the error is the colour term alone,
// computed here from textbook values: L*(Y) = 116·Y^(1/3) − 16 for greys (a* = b* = 0), and the
// sRGB green and blue primaries' L*a*b* (D65) of (87.737, −86.185, 83.181) and
// (32.303, 79.197, −107.864), Hunt-adjusted by 0.01·L*.
TEST(Flip, UniformGreysMatchAHandComputation) {
  const float a = 0.5f, b = 0.6f;
  const std::vector<glm::vec3> ia(std::size_t(kW * kH), glm::vec3(a)),
      ib(std::size_t(kW * kH), glm::vec3(b));
  const FlipResult r = flip(ia, ib, kW, kH);
  const double deltaL = 116.0 * (std::cbrt(double(b)) - std::cbrt(double(a)));
  const double gL = 87.737, bL = 32.303;
  const double ga = -86.185 * gL / 100, gb = 83.181 * gL / 100;
  const double ba = 79.197 * bL / 100, bb = -107.864 * bL / 100;
  const double cMax = std::pow(std::abs(gL - bL) + std::hypot(ga - ba, gb - bb), 0.7);
  const double expected = 0.95 / (0.4 * cMax) * std::pow(deltaL, 0.7);
  for (float e : r.error) EXPECT_NEAR(e, expected, 2e-3 * expected);
  EXPECT_NEAR(r.mean, expected, 2e-3 * expected);
}

TEST(Flip, GrowsMonotonicallyWithNoiseAmplitude) {
  const auto img = testImage();
  double previous = 0.0;
  for (float amplitude : {0.005f, 0.01f, 0.02f, 0.05f, 0.1f, 0.2f, 0.4f}) {
    const double m = flip(img, withNoise(img, amplitude), kW, kH).mean;
    EXPECT_GT(m, previous) << "amplitude " << amplitude;
    previous = m;
  }
  EXPECT_GT(previous, 0.3);
}

TEST(Flip, OnePixelChangeStaysLocal) {
  const std::vector<glm::vec3> grey(std::size_t(kW * kH), glm::vec3(0.5f));
  auto changed = grey;
  const int cx = 20, cy = 17;
  changed[std::size_t(cy * kW + cx)] = glm::vec3(1.0f, 0.2f, 0.2f);
  const FlipResult r = flip(grey, changed, kW, kH);
  // At 67 ppd the widest kernel (blue-yellow CSF) has radius 10 pixels, the feature kernels 9.
  float peak = 0.0f;
  int peakX = -1, peakY = -1;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float e = r.error[std::size_t(y * kW + x)];
      if (std::max(std::abs(x - cx), std::abs(y - cy)) > 10) {
        EXPECT_EQ(e, 0.0f) << x << "," << y;
      }
      if (e > peak) peak = e, peakX = x, peakY = y;
    }
  EXPECT_GT(peak, 0.1f);
  EXPECT_LE(std::abs(peakX - cx), 1);
  EXPECT_LE(std::abs(peakY - cy), 1);
  EXPECT_LT(r.mean, 0.02);
}

TEST(Flip, SymmetricAndRejectsBadSizes) {
  const auto img = testImage();
  const auto noisy = withNoise(img, 0.1f);
  const FlipResult ab = flip(img, noisy, kW, kH), ba = flip(noisy, img, kW, kH);
  for (std::size_t i = 0; i < ab.error.size(); ++i) EXPECT_FLOAT_EQ(ab.error[i], ba.error[i]);
  EXPECT_THROW(flip(img, img, kW + 1, kH), std::invalid_argument);
  EXPECT_THROW(flip(img, img, kW, kH, 0.0), std::invalid_argument);
}

TEST(Flip, PixelsPerDegreeOfTheDefaultObserver) { EXPECT_NEAR(kFlipDefaultPpd, 67.02, 0.01); }

}  // namespace
}  // namespace sdfstream::reference
