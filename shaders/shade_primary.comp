#version 450
// Primary-hit shading of the demo frames (demo/gi_shading.h; math in shade_primary.glsl, shared
// with the CPU reference): one invocation per camera ray, spread over rows of 64 x 16384 threads.
// Bindings: 0 rays, 1 shaded hits (written), 2 page tables, 3 distance atlas (or,
// where specialization constant 0 says so, the corner atlas: the same distances by cell), 4 albedo atlas,
// 5 emission atlas, 6 cascade params (as trace_stack.comp), 7 lights, 8 light-cache radiance,
// 9-16 moving objects (object_bindings.glsl, gi/object_scene.h; zero instances when none),
// 17 given primary surfaces (read with options.z == kShadePrimaryGiven, one per ray).
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/light_layout.h"
#include "shaders/shared/color_codec.h"
#include "shaders/shared/shade_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Rays { TraceRay rays[]; };
layout(std430, binding = 1) writeonly buffer Shaded { ShadedHit shaded[]; };
layout(std430, binding = 2) readonly buffer PageTable { uint pageTable[]; };
layout(std430, binding = 3) readonly buffer DistanceAtlas { uint distanceAtlas[]; };
layout(std430, binding = 3) readonly buffer CornerAtlas { uvec4 cornerAtlas[]; };
layout(std430, binding = 4) readonly buffer AlbedoAtlas { uint albedoAtlas[]; };
layout(std430, binding = 5) readonly buffer EmissionAtlas { uint emissionAtlas[]; };
layout(std430, binding = 6) readonly buffer Cascades { CascadeTraceParams cascades[]; };
layout(std430, binding = 7) readonly buffer Lights { GpuLight lights[]; };
layout(std430, binding = 8) readonly buffer LightRadiance { uint lightRadiance[]; };
layout(std430, binding = 17) readonly buffer Surfaces { PrimarySurface surfaces[]; };

layout(push_constant) uniform Push { ShadePushConstants pc; };

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_CELL_CORNERS(i) cornerAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#define LIGHT_AT(i) lights[i]
#define LIGHT_RADIANCE(m) lightRadiance[m]
#define OBJ_BINDING_BASE 9
#include "shaders/object_bindings.glsl"
#include "shaders/sdf_trace.glsl"
#include "shaders/object_trace.glsl"
#include "shaders/light_math.glsl"
#include "shaders/shade_primary.glsl"

void main() {
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
  if (id >= pc.counts.x) return;
  shaded[id] = pc.options.z == kShadePrimaryGiven ? shadeGivenSurface(rays[id], surfaces[id], pc)
                                                  : shadePrimary(rays[id], pc);
}
