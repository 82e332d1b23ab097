// Colour packing shared by C++ and GLSL: RGBA8 for albedo and RGB9E5 (shared exponent, as in
// VK_FORMAT_E5B9G9R9_UFLOAT_PACK32) for HDR emission, so emission above 1 survives.
#ifndef SDFSTREAM_COLOR_CODEC_H
#define SDFSTREAM_COLOR_CODEC_H

#include "shaders/shared/glsl_cpp.h"

SDF_BEGIN_NAMESPACE

#ifdef __cplusplus
inline
#endif
vec4 unpackAlbedo(uint v) {
  return vec4(float(v & 255u), float((v >> 8) & 255u), float((v >> 16) & 255u),
              float((v >> 24) & 255u)) * (1.0f / 255.0f);
}

#ifdef __cplusplus
inline
#endif
vec3 unpackRgb9e5(uint v) {
  // exponent bias 15, 9 mantissa bits: value = mantissa * 2^(exp - 15 - 9)
  float scale = exp2(float(int(v >> 27) - 24));
  return vec3(float(v & 511u), float((v >> 9) & 511u), float((v >> 18) & 511u)) * scale;
}

// Linear RGB -> RGB9E5, the inverse of unpackRgb9e5 (EXT_texture_shared_exponent's algorithm,
// round to nearest): negative and NaN channels -> 0, channels above 65408 (the largest encodable
// value) clamped. The one definition for the GPU (light cache) and the importer
// (world/color_pack.h forwards here), so both write the same bits. The exponent and the scale are
// taken from / built from float bits rather than log2/exp2, which GPUs only approximate.
#ifdef __cplusplus
using glm::floatBitsToUint;
using glm::uintBitsToFloat;
inline
#endif
uint packRgb9e5(vec3 rgb) {
  float kMax = 65408.0f;  // (2^9 - 1) / 2^9 * 2^(31 - 15)
  // `v > 0` is false for NaN, so NaN becomes 0 in both languages.
  float r = rgb.x > 0.0f ? (rgb.x < kMax ? rgb.x : kMax) : 0.0f;
  float g = rgb.y > 0.0f ? (rgb.y < kMax ? rgb.y : kMax) : 0.0f;
  float b = rgb.z > 0.0f ? (rgb.z < kMax ? rgb.z : kMax) : 0.0f;
  float m = r > g ? r : g;
  m = m > b ? m : b;
  if (m <= 0.0f) return 0u;
  // floor(log2(m)) for a normal float; denormals read -127 and are caught by the -16 floor.
  int e = int((floatBitsToUint(m) >> 23u) & 255u) - 127;
  int exponent = (e > -16 ? e : -16) + 16;  // max(-bias - 1, floor(log2 m)) + 1 + bias
  // scale = 2^(24 - exponent) = 2^-(exponent - bias - mantissa bits), exact: a power of two.
  float scale = uintBitsToFloat(uint(127 + 24 - exponent) << 23u);
  if (uint(m * scale + 0.5f) == 512u) {  // rounding carried into a tenth bit
    exponent += 1;
    scale *= 0.5f;
  }
  exponent = exponent < 31 ? exponent : 31;
  uint mr = uint(r * scale + 0.5f);
  uint mg = uint(g * scale + 0.5f);
  uint mb = uint(b * scale + 0.5f);
  mr = mr < 511u ? mr : 511u;
  mg = mg < 511u ? mg : 511u;
  mb = mb < 511u ? mb : 511u;
  return mr | (mg << 9u) | (mb << 18u) | (uint(exponent) << 27u);
}

SDF_END_NAMESPACE

#endif
