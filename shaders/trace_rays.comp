#version 450
// Sphere-traces a batch of rays through one cascade (see sdf_trace.glsl for the math, shared
// with the CPU reference in gi/cpu_tracer.cpp). Bindings: 0 rays, 1 hits, 2 page table,
// 3 distance atlas, 4 albedo atlas, 5 emission atlas.
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/color_codec.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Rays { TraceRay rays[]; };
layout(std430, binding = 1) writeonly buffer Hits { TraceHit hits[]; };
layout(std430, binding = 2) readonly buffer PageTable { uint pageTable[]; };
layout(std430, binding = 3) readonly buffer DistanceAtlas { uint distanceAtlas[]; };
layout(std430, binding = 4) readonly buffer AlbedoAtlas { uint albedoAtlas[]; };
layout(std430, binding = 5) readonly buffer EmissionAtlas { uint emissionAtlas[]; };

layout(push_constant) uniform Push { TracePushConstants pc; };

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#include "shaders/sdf_trace.glsl"

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (id >= pc.rayCount) return;
  TraceRay ray = rays[id];
  vec3 origin = ray.originTMin.xyz;
  vec3 dir = ray.dirTMax.xyz;
  SdfTraceResult r = sdfTrace(origin, dir, ray.originTMin.w, ray.dirTMax.w, pc.maxSteps,
                              pc.hitEpsilon, pc.toroidalOffset);
  TraceHit h;
  h.steps = r.steps;
  h.flags = (r.hit ? kHitFlagHit : 0u) | (r.ranOutOfSteps ? kHitFlagRanOutOfSteps : 0u) |
            (r.missingData ? kHitFlagMissingData : 0u);
  if (r.hit) {
    vec3 n = sdfNormal(r.position, pc.toroidalOffset);
    h.normalT = vec4(n, r.t);
    h.albedo = albedoAtlas[r.slot * kBrickMaterialCount + r.cell];
    h.emission = emissionAtlas[r.slot * kBrickMaterialCount + r.cell];
  } else {
    h.normalT = vec4(0.0, 0.0, 0.0, -1.0);
    h.albedo = 0u;
    h.emission = 0u;
  }
  hits[id] = h;
}
