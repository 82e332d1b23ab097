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

SDF_END_NAMESPACE

#endif
