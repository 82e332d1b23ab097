#version 450
// Static light cache update (gi/light_cache.h; math in light_math.glsl, shared with the CPU
// reference LightCacheCpu): one workgroup per listed page (y = index into the page list). Each
// listed page that is resident gets its 512 cells relit and written as RGB9E5 into the light
// atlas at slot * 512 + cell, the indexing of the albedo and emission atlas. Pages not listed
// keep their cached light (Godot SDFGI slides, "Caching light hits": a static light texture
// computed once and updated in dirty regions).
// Only the surface cells (lightCellIsSurface, ~10-20% of a page) trace shadow rays, and they are
// scattered through the page: a thread per cell left most lanes of a warp idle while one lane
// marched 256 steps. So the workgroup first writes every other cell's emission and compacts the
// surface cells into shared memory, then lights them 64 at a time with full warps. Each cell's
// value is lightCacheCellRadiance's, as before: only the order of work changed.
// Bindings: 0 page list (global page-table indices, cascade * 4096 + toroidal entry), 1 lights,
// 2 light atlas (written), 3 page tables, 4 distance atlas (or,
// where specialization constant 0 says so, the corner atlas: the same distances by cell), 5 albedo
// atlas, 6 emission atlas,
// 7 cascade params (as trace_stack.comp), 8-15 moving objects (object_bindings.glsl).
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/light_layout.h"
#include "shaders/shared/color_codec.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer PageList { uint pageList[]; };
layout(std430, binding = 1) readonly buffer Lights { GpuLight lights[]; };
layout(std430, binding = 2) writeonly buffer LightAtlas { uint lightAtlas[]; };
layout(std430, binding = 3) readonly buffer PageTable { uint pageTable[]; };
layout(std430, binding = 4) readonly buffer DistanceAtlas { uint distanceAtlas[]; };
layout(std430, binding = 4) readonly buffer CornerAtlas { uvec4 cornerAtlas[]; };
layout(std430, binding = 5) readonly buffer AlbedoAtlas { uint albedoAtlas[]; };
layout(std430, binding = 6) readonly buffer EmissionAtlas { uint emissionAtlas[]; };
layout(std430, binding = 7) readonly buffer Cascades { CascadeTraceParams cascades[]; };

layout(push_constant) uniform Push { LightCachePushConstants pc; };

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_CELL_CORNERS(i) cornerAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#define LIGHT_AT(i) lights[i]
// Moving objects block shadow rays (bindings 8-15, gi/object_scene.h; zero instances when none).
#define OBJ_BINDING_BASE 8
#include "shaders/object_bindings.glsl"
#include "shaders/sdf_trace.glsl"
#include "shaders/object_trace.glsl"
#include "shaders/light_math.glsl"

shared uint surfaceCells[kBrickMaterialCount];
shared uint surfaceCount;

void main() {
  uint item = gl_WorkGroupID.y;
  uint lane = gl_LocalInvocationID.x;
  if (lane == 0u) surfaceCount = 0u;
  barrier();
  // Uniform per workgroup: every invocation returns or none does (barriers below).
  if (item >= pc.counts.x) return;
  uint global = pageList[item];
  uint cascade = global / kCascadePageCount;
  if (cascade >= pc.counts.z) return;
  uint entry = pageTable[global];
  if ((entry & kPageResidentBit) == 0u) return;  // nothing to light (yet)
  uint slot = entry & kPagePayloadMask;
  ivec3 page = lightPageOfEntry(global % kCascadePageCount, cascades[cascade].toroidal);
  for (uint cell = lane; cell < kBrickMaterialCount; cell += gl_WorkGroupSize.x) {
    if (pc.counts.y > 0u && lightCellIsSurface(cascade, page, cell))
      surfaceCells[atomicAdd(surfaceCount, 1u)] = cell;
    else  // emission only: lightCacheCellRadiance returns before any shadow ray
      lightAtlas[slot * kBrickMaterialCount + cell] =
          packRgb9e5(lightCacheCellRadiance(cascade, page, slot, cell, pc.counts.y, pc.params.x,
                                            pc.counts.w, pc.params.y, pc.counts.z));
  }
  barrier();
  uint count = surfaceCount;
  for (uint i = lane; i < count; i += gl_WorkGroupSize.x) {
    uint cell = surfaceCells[i];
    vec3 radiance = lightCacheCellRadiance(cascade, page, slot, cell, pc.counts.y, pc.params.x,
                                           pc.counts.w, pc.params.y, pc.counts.z);
    lightAtlas[slot * kBrickMaterialCount + cell] = packRgb9e5(radiance);
  }
}
