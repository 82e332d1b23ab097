#version 450
// Sphere-traces rays through the whole cascade stack (sdfTraceStack in sdf_trace.glsl, shared
// with the CPU reference gi/cpu_tracer.cpp). Rays and hit distances are in cascade-0 voxels
// relative to cascade 0's minimum corner. Bindings: 0 rays, 1 hits, 2 page tables (cascade-major,
// 4096 entries each), 3 distance atlas or, where specialization constant 0 says so, the corner
// atlas (the distances by cell), 4 albedo atlas, 5 emission atlas, 6 cascade params.
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Rays { TraceRay rays[]; };
layout(std430, binding = 1) writeonly buffer Hits { TraceHit hits[]; };
layout(std430, binding = 2) readonly buffer PageTable { uint pageTable[]; };
layout(std430, binding = 3) readonly buffer DistanceAtlas { uint distanceAtlas[]; };
layout(std430, binding = 3) readonly buffer CornerAtlas { uvec4 cornerAtlas[]; };
layout(std430, binding = 4) readonly buffer AlbedoAtlas { uint albedoAtlas[]; };
layout(std430, binding = 5) readonly buffer EmissionAtlas { uint emissionAtlas[]; };
layout(std430, binding = 6) readonly buffer Cascades { CascadeTraceParams cascades[]; };

layout(push_constant) uniform Push { TraceStackPushConstants pc; };

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#define SDF_CELL_CORNERS(i) cornerAtlas[i]
#include "shaders/sdf_trace.glsl"

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (id >= pc.rayCount) return;
  TraceRay ray = rays[id];
  SdfStackResult s =
      sdfTraceStackFrom(ray.originTMin.xyz, ray.dirTMax.xyz, ray.originTMin.w, ray.dirTMax.w,
                        pc.maxSteps, pc.hitEpsilon, pc.firstCascade, pc.cascadeCount);
  TraceHit h;
  h.steps = s.steps;
  h.flags = (s.r.hit ? kHitFlagHit : 0u) | (s.r.ranOutOfSteps ? kHitFlagRanOutOfSteps : 0u) |
            (s.r.missingData ? kHitFlagMissingData : 0u) | (s.fellBack ? kHitFlagFellBack : 0u) |
            (s.cascade << kHitCascadeShift);
  if (s.r.hit) {
    vec3 n = sdfNormal(s.r.position, cascades[s.cascade].toroidal);
    h.normalT = vec4(n, s.t0);
    h.albedo = albedoAtlas[s.r.slot * kBrickMaterialCount + s.r.cell];
    h.emission = emissionAtlas[s.r.slot * kBrickMaterialCount + s.r.cell];
  } else {
    h.normalT = vec4(0.0, 0.0, 0.0, -1.0);
    h.albedo = 0u;
    h.emission = 0u;
  }
  hits[id] = h;
}
