// CPU encoders for the brick material formats decoded by shaders/shared/color_codec.h: albedo as
// RGBA8 with sRGB-encoded RGB (alpha linear), emission as RGB9E5 (shared exponent, the bit layout
// of VK_FORMAT_E5B9G9R9_UFLOAT_PACK32). Pure functions, safe on any input (NaN → 0).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace sdfstream {

inline float linearToSrgb(float c) {
  if (!(c > 0.0f)) return 0.0f;  // also catches NaN
  if (c >= 1.0f) return 1.0f;
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

// Linear RGBA in [0,1] → RGBA8, R in the low byte (matches unpackAlbedo).
inline std::uint32_t packAlbedo(glm::vec4 linear) {
  auto byte = [](float v) {
    return std::uint32_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
  };
  float a = linear.a > 0.0f ? linear.a : 0.0f;
  return byte(linearToSrgb(linear.r)) | byte(linearToSrgb(linear.g)) << 8 |
         byte(linearToSrgb(linear.b)) << 16 | byte(a) << 24;
}

// Linear RGB ≥ 0 → RGB9E5 (EXT_texture_shared_exponent's algorithm, round to nearest): exponent
// bias 15, 9-bit mantissas, value = mantissa · 2^(e − 24). Negative/NaN → 0, above 65408 clamped.
inline std::uint32_t packRgb9e5(glm::vec3 rgb) {
  constexpr int kBias = 15, kMantissaBits = 9, kMaxExponent = 31;
  constexpr float kMaxValue = 511.0f / 512.0f * 65536.0f;  // (2^9-1)/2^9 · 2^(31-15)
  auto clampChannel = [&](float v) { return v > 0.0f ? std::min(v, kMaxValue) : 0.0f; };
  float r = clampChannel(rgb.r), g = clampChannel(rgb.g), b = clampChannel(rgb.b);
  float maxc = std::max(r, std::max(g, b));
  if (maxc <= 0.0f) return 0;
  int exp2;
  std::frexp(maxc, &exp2);  // maxc = f · 2^exp2, f in [0.5, 1): floor(log2(maxc)) = exp2 - 1
  int shared = std::max(-kBias - 1, exp2 - 1) + 1 + kBias;
  float scale = std::ldexp(1.0f, -(shared - kBias - kMantissaBits));
  if (int(std::floor(maxc * scale + 0.5f)) == (1 << kMantissaBits)) {
    ++shared;
    scale *= 0.5f;
  }
  shared = std::min(shared, kMaxExponent);
  auto mant = [&](float v) {
    return std::uint32_t(std::min(511.0f, std::floor(v * scale + 0.5f)));
  };
  return mant(r) | mant(g) << 9 | mant(b) << 18 | std::uint32_t(shared) << 27;
}

}  // namespace sdfstream
