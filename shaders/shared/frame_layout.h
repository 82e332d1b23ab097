// The GPU-composed picture of a view (GiRenderer::renderPicture, demo/gi_shading.h): the camera
// rays pass (camera_rays.comp), then the shading pass, then frame_compose.comp, which samples the
// probe field per pixel as an engine's shader would (include/sdfstream/probe_sample.glsl), adds
// the indirect light, tone-maps and packs the picture. Push constants and the tone map, shared by
// C++ and GLSL (STYLE.md habit 1); demo/frame_image.cpp's CPU tone map is the same function.
#ifndef SDFSTREAM_FRAME_LAYOUT_H
#define SDFSTREAM_FRAME_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"

#ifdef __cplusplus
#include <cmath>
#endif

SDF_BEGIN_NAMESPACE

// One primary ray per pixel centre (gi/camera.h primaryRaysFrom, demo/gi_shading.h cameraRays),
// in stack space: dir = normalize(forward + u·right + v·up), u = 2(x + 0.5)/width − 1,
// v = 1 − 2(y + 0.5)/height (right and up already scaled by the half-angle tangents). A camera
// outside the stack's outermost window [windowLo, windowHi) starts each ray where it enters it.
struct CameraRaysPush {
  vec4 origin;    // xyz: the camera, stack space
  vec4 forward;   // xyz: unit view direction
  vec4 right;     // xyz: right · tan(fovY/2) · aspect
  vec4 up;        // xyz: up · tan(fovY/2)
  vec4 windowLo;  // xyz: the outermost window's minimum corner (stack space)
  vec4 windowHi;  // xyz: its maximum corner; w: 1 when there is a window, else 0
  uvec4 size;     // x: width, y: height
};

// What frame_compose.comp writes (FrameComposePush.size.z), as the viewer's view modes.
SDF_CONST uint kFrameFinal = 0u;     // direct + indirect (with kFrameAddIndirect)
SDF_CONST uint kFrameDirect = 1u;    // direct light only
SDF_CONST uint kFrameIndirect = 2u;  // indirect light only, params.y times brighter
SDF_CONST uint kFrameAlbedo = 3u;    // the hit's sRGB albedo as stored
SDF_CONST uint kFrameNormals = 4u;   // n · 0.5 + 0.5
SDF_CONST uint kFrameCascade = 5u;   // the cascade the primary hit lies in, one colour each
SDF_CONST uint kFrameResidency = 6u;  // green: hit on streamed bricks of its own cascade;
                                      // orange: a page not streamed yet sent the ray to a
                                      // coarser cascade; red: a miss on missing data
SDF_CONST uint kFrameProbeStates = 7u;  // the state of the probe nearest the hit, finest volume:
                                        // grey off, blue sleeping, green awake, red vigilant
SDF_CONST uint kFrameObjectRegions = 8u;  // the 8³ macro region (finest region cascade) of the
                                          // hit: dark grey none listed, yellow one object,
                                          // orange two or three, red four or more; object hits
                                          // white; outside every region grid black (no
                                          // objects at all: every hit dark grey)

// FrameComposePush.size.w bits.
SDF_CONST uint kFrameProbesBound = 1u;  // bindings 3-10 hold a probe field (GI on)
SDF_CONST uint kFrameAddIndirect = 2u;  // kFrameFinal adds the indirect light

struct FrameComposePush {
  uvec4 size;   // x: width, y: height, z: kFrame*, w: kFrameProbesBound | kFrameAddIndirect
  vec4 params;  // x: exposure scale 2^stops; y: kFrameIndirect's extra scale; zw unused
};

// Hill's fit of the ACES RRT + ODT (ACESFitted.hlsl), on linear sRGB; NaN and negative channels
// become 0, the result is clamped to [0, 1].
#ifdef __cplusplus
using glm::clamp;
using std::floor;
using std::pow;
inline
#endif
vec3 frameAcesFitted(vec3 c) {
  c = vec3(c.x > 0.0f ? c.x : 0.0f, c.y > 0.0f ? c.y : 0.0f, c.z > 0.0f ? c.z : 0.0f);
  vec3 v = vec3(0.59719f * c.x + 0.35458f * c.y + 0.04823f * c.z,
                0.07600f * c.x + 0.90834f * c.y + 0.01566f * c.z,
                0.02840f * c.x + 0.13383f * c.y + 0.83777f * c.z);
  v = (v * (v + 0.0245786f) - 0.000090537f) / (v * (0.983729f * v + 0.4329510f) + 0.238081f);
  vec3 o = vec3(1.60475f * v.x - 0.53108f * v.y - 0.07367f * v.z,
                -0.10208f * v.x + 1.10813f * v.y - 0.00605f * v.z,
                -0.00327f * v.x - 0.07276f * v.y + 1.07602f * v.z);
  return clamp(o, vec3(0.0f), vec3(1.0f));
}

// sRGB-encoded [0, 1] -> linear (the sRGB EOTF), for albedo and texels read back as codes.
#ifdef __cplusplus
inline
#endif
float frameSrgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : pow((c + 0.055f) / 1.055f, 2.4f);
}

// Linear [0, 1] -> sRGB-encoded 8-bit code, rounded to nearest.
#ifdef __cplusplus
inline
#endif
uint frameSrgb8(float c) {
  c = clamp(c, 0.0f, 1.0f);
  float s = c <= 0.0031308f ? c * 12.92f : 1.055f * pow(c, 1.0f / 2.4f) - 0.055f;
  return uint(floor(s * 255.0f + 0.5f));
}

SDF_END_NAMESPACE

#ifdef __cplusplus
static_assert(sizeof(sdfstream::gpu_shared::CameraRaysPush) == 112);
static_assert(sizeof(sdfstream::gpu_shared::FrameComposePush) == 32);
#endif

#endif
