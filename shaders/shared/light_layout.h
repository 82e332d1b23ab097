// Direct lights and sky, shared by C++ and GLSL (STYLE.md habit 1): the light cache
// (gi/light_cache.h, shaders/light_cache.comp), the probe update (misses return the sky) and the
// Embree path tracer (reference/path_tracer.h) all read the same description, so the GI and its
// ground truth light the same scene.
//
// Units: positions in cascade-0 voxels relative to cascade 0's minimum corner on the GPU; the
// C++ scene description (gi/scene_lights.h) keeps world metres and converts. Colours are linear
// RGB. A light's `colorIntensity.rgb * colorIntensity.w` is:
//  - sun: irradiance on a surface facing it (W/m² per unit of the scene's radiance scale);
//  - point / spot: intensity (radiance × area), falling off with 1 / distance² (distance in
//    metres, so the GPU multiplies voxel distances by voxelSize0; see LightCachePushConstants).
#ifndef SDFSTREAM_LIGHT_LAYOUT_H
#define SDFSTREAM_LIGHT_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"

SDF_BEGIN_NAMESPACE

SDF_CONST uint kLightSun = 0u;    // directional: positionType.xyz unused, direction.xyz = towards the light
SDF_CONST uint kLightPoint = 1u;  // omni: positionType.xyz = position
SDF_CONST uint kLightSpot = 2u;   // cone: position + direction (the way the spot points) + angles
SDF_CONST uint kMaxLights = 16u;

struct GpuLight {
  vec4 positionType;    // xyz: position (cascade-0 voxels; unused by the sun); w: kLight* as float
  vec4 direction;       // xyz: unit; sun: towards the light; spot: the way the spot shines.
                        // w: cos(outer cone half-angle) (spot only)
  vec4 colorIntensity;  // rgb: linear colour; w: intensity (see the header)
  vec4 shape;           // x: cos(inner cone half-angle) (spot); y: range in metres (0 = none);
                        // z: soft-shadow sharpness k (penumbra ~ 1/k; 0 = hard shadows);
                        // w: 1 = casts shadows, 0 = does not
};

// Sky seen by rays that leave the stack: gradient from horizon to zenith along +y (world up).
struct GpuSky {
  vec4 zenith;   // rgb: radiance straight up; w unused
  vec4 horizon;  // rgb: radiance at and below the horizon; w unused
};

// Push constants of light_cache.comp (gi/light_cache.h): relight the listed pages' cells.
struct LightCachePushConstants {
  uvec4 counts;  // x: listed pages; y: lights (<= kMaxLights); z: cascades; w: max shadow steps
                 //                                                                    (0..15)
  vec4 params;   // x: cascade-0 voxel size in metres; y: hit epsilon (voxels); z: 1 when the
                 // atlas binding holds the corner atlas (gi/gpu_stack_scene.h), else 0; w: 0
                 //                                                                   (16..31)
  GpuSky sky;    // not added to the cells (probe rays that miss see it; adding it here would
                 // count it twice); carried for passes that share these constants     (32..63)
};

SDF_END_NAMESPACE

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(sdfstream::gpu_shared::GpuLight) == 64);
static_assert(sizeof(sdfstream::gpu_shared::GpuSky) == 32);
static_assert(sizeof(sdfstream::gpu_shared::LightCachePushConstants) == 64);
static_assert(offsetof(sdfstream::gpu_shared::LightCachePushConstants, params) == 16);
static_assert(offsetof(sdfstream::gpu_shared::LightCachePushConstants, sky) == 32);
#endif

#endif
