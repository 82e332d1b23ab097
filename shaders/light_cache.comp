#version 450
// Static light cache update (gi/light_cache.h; math in light_math.glsl, shared with the CPU
// reference LightCacheCpu): one workgroup per listed page (y = index into the page list). Each
// listed page that is resident gets its 512 cells relit and written as RGB9E5 into the light
// atlas at slot * 512 + cell, the indexing of the albedo and emission atlas. Pages not listed
// keep their cached light (Godot SDFGI slides, "Caching light hits": a static light texture
// computed once and updated in dirty regions).
// Only the surface cells that a shadow-casting light reaches (lightCellMarches: about half of the
// ~10-20% of a page within the surface band) trace shadow rays, and they are scattered through
// the page: a thread per cell left most lanes of a warp idle while one lane marched 256 steps.
// So the workgroup first lights every other cell (emission, or a surface cell no light reaches:
// no march) and compacts the marching cells with their surface points into shared memory, then
// lights them 64 at a time with full warps. Each cell's value is lightCacheCellRadiance's: only
// the order of work changed (listing every surface cell, as before, left the facing-away ones
// idling in the marching warps: `bench gi --gpu-table` counts both mappings' warp-steps).
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
shared vec3 surfaceNormals[kBrickMaterialCount];
shared vec3 surfacePoints[kBrickMaterialCount];
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
    uint m = slot * kBrickMaterialCount + cell;
    // As lightCacheCellRadiance, split where a shadow ray would be marched.
    LightCellSurface surface;
    surface.surface = false;
    if (pc.counts.y > 0u) surface = lightCellSurface(cascade, page, cell);
    if (lightCellMarches(surface, pc.counts.y, pc.params.x, pc.counts.z)) {
      uint i = atomicAdd(surfaceCount, 1u);
      surfaceCells[i] = cell;
      surfaceNormals[i] = surface.n;
      surfacePoints[i] = surface.p0;
    } else {
      lightAtlas[m] = packRgb9e5(surface.surface
                                     ? lightCacheSurfaceRadiance(m, surface, pc.counts.y,
                                                                 pc.params.x, pc.counts.w,
                                                                 pc.params.y, pc.counts.z)
                                     : unpackRgb9e5(SDF_EMISSION(m)));
    }
  }
  barrier();
  uint count = surfaceCount;
  for (uint i = lane; i < count; i += gl_WorkGroupSize.x) {
    uint m = slot * kBrickMaterialCount + surfaceCells[i];
    LightCellSurface surface;
    surface.surface = true;
    surface.n = surfaceNormals[i];
    surface.p0 = surfacePoints[i];
    lightAtlas[m] = packRgb9e5(lightCacheSurfaceRadiance(m, surface, pc.counts.y, pc.params.x,
                                                         pc.counts.w, pc.params.y, pc.counts.z));
  }
}
