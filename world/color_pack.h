// CPU encoders for the brick material formats decoded by shaders/shared/color_codec.h: albedo as
// RGBA8 with sRGB-encoded RGB (alpha linear), emission as RGB9E5 (shared exponent, the bit layout
// of VK_FORMAT_E5B9G9R9_UFLOAT_PACK32). Pure functions, safe on any input (NaN → 0).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "shaders/shared/color_codec.h"

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

// Linear RGB ≥ 0 → RGB9E5: the shared definition in shaders/shared/color_codec.h (the light cache
// shader packs with the same function, so importer and GPU write the same bits). Negative/NaN → 0,
// above 65408 clamped.
inline std::uint32_t packRgb9e5(glm::vec3 rgb) { return gpu_shared::packRgb9e5(rgb); }

}  // namespace sdfstream
