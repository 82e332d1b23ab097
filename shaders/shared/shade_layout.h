// The primary-hit shading pass of the demo frames (shaders/shade_primary.comp, math in
// shaders/shade_primary.glsl, CPU reference in demo/gi_shading.cpp): its push constants and its
// per-pixel result, shared by C++ and GLSL (STYLE.md habit 1).
//
// Units: rays in cascade-0 voxels relative to cascade 0's minimum corner (the stack traversal's
// space, CascadeStackImage::toStack); radiance linear RGB in the scene's radiance scale
// (shaders/shared/light_layout.h).
#ifndef SDFSTREAM_SHADE_LAYOUT_H
#define SDFSTREAM_SHADE_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"
#include "shaders/shared/light_layout.h"

SDF_BEGIN_NAMESPACE

// Where a hit's direct light comes from (ShadePushConstants.options.x).
SDF_CONST uint kShadeDirectPixel = 0u;  // lightIrradiance (light_math.glsl) at the hit point
                                        // itself: SDF soft shadows per pixel
SDF_CONST uint kShadeDirectCache = 1u;  // the static light cache's RGB9E5 value of the hit's
                                        // material voxel (one value per voxel, blockier); moving
                                        // objects have no cache entry and are always lit per pixel

// ShadedHit.flags bit beside sdf_layout.h's kHitFlag* (bits 0-3) and the hit cascade (bits 8-11):
// the primary hit is a moving object (shaders/object_trace.glsl), nearer than the static hit.
// normalT then holds the object's normal and hit distance, albedo/emission its material sample,
// and the cascade bits 0.
SDF_CONST uint kShadeFlagObject = 0x10000u;

// Where a pixel's primary surface comes from (ShadePushConstants.options.z).
SDF_CONST uint kShadePrimaryTrace = 0u;  // the camera ray traced through the cascade stack
SDF_CONST uint kShadePrimaryGiven = 1u;  // PrimarySurface i, rasterized from the scene's
                                         // triangles (raster/mesh_view_raster.h); the ray still
                                         // searches the moving objects in front of it

struct ShadePushConstants {
  uvec4 counts;   // x: rays; y: lights (<= kMaxLights); z: cascades; w: trace max steps (0..15)
  vec4 params;    // x: cascade-0 voxel size (m); y: trace hit epsilon (voxels);
                  // z: shadow hit epsilon (voxels); w unused                        (16..31)
  uvec4 options;  // x: kShadeDirect*; y: shadow max steps; z: kShadePrimary*; w: 1 when the
                  // atlas binding holds the corner atlas (gi/gpu_stack_scene.h), else 0 (32..47)
  GpuSky sky;     // seen by rays that miss                                          (48..79)
  // Stack-space AABB of every moving object's bounds (ObjectInstanceGpu boundsMin/Max), padded;
  // min > max when there are none. Rays, primary or shadow, search the objects only over their
  // stretch inside it: most shadow rays leave the objects' height band within a few metres, and
  // the region walk they skip costs as much as the static shadow walk. w unused.
  vec4 objectsMin;  //                                                                (80..95)
  vec4 objectsMax;  //                                                               (96..111)
};

// One pixel's primary hit and its direct radiance. t < 0 (normalT.w) means a miss.
struct ShadedHit {
  vec4 normalT;   // xyz: unit SDF normal at the hit; w: hit distance, cascade-0 voxels (0..15)
  vec4 direct;    // rgb: hit: outgoing direct radiance, emission + albedo/π · E_direct;
                  // miss: sky radiance along the ray. w: how far along the normal the
                  // hit's probe query starts, cascade-0 voxels (a given surface lying
                  // inside the SDF's surface; 0 for traced hits)                    (16..31)
  uint albedo;    // RGBA8 sRGB-encoded albedo of the hit material voxel (0 on a miss) (32..35)
  uint emission;  // RGB9E5 linear emission of the hit material voxel               (36..39)
  uint steps;     // sphere-tracing iterations of the primary ray (static + object)  (40..43)
  uint flags;     // kHitFlag* bits, the hit cascade (sdf_layout.h), kShadeFlagObject (44..47)
};

// A pixel's primary surface given rather than traced (kShadePrimaryGiven): the nearest triangle
// at the pixel, resolved from the visibility buffer with the scene's own materials.
struct PrimarySurface {
  vec4 position;  // xyz: the surface point, stack space (cascade-0 voxels); w: 1, or 0 for
                  // nothing (the sky)                                               (0..15)
  vec4 normalT;   // xyz: unit geometric normal, facing the camera; w: distance from the
                  // camera, cascade-0 voxels                                        (16..31)
  uint albedo;    // RGBA8 sRGB-encoded base colour (color_codec.h)                 (32..35)
  uint emission;  // RGB9E5 linear emission                                         (36..39)
  uint pad0;
  uint pad1;
};

SDF_END_NAMESPACE

#ifdef __cplusplus
#include <cstddef>
// 112 bytes: within the 128 bytes of push constants every Vulkan device offers.
static_assert(sizeof(sdfstream::gpu_shared::ShadePushConstants) == 112);
static_assert(offsetof(sdfstream::gpu_shared::ShadePushConstants, sky) == 48);
static_assert(offsetof(sdfstream::gpu_shared::ShadePushConstants, objectsMin) == 80);
static_assert(offsetof(sdfstream::gpu_shared::ShadePushConstants, objectsMax) == 96);
static_assert(sizeof(sdfstream::gpu_shared::ShadedHit) == 48);
static_assert(offsetof(sdfstream::gpu_shared::ShadedHit, albedo) == 32);
static_assert(offsetof(sdfstream::gpu_shared::ShadedHit, flags) == 44);
static_assert(sizeof(sdfstream::gpu_shared::PrimarySurface) == 48);
static_assert(offsetof(sdfstream::gpu_shared::PrimarySurface, albedo) == 32);
#endif

#endif
