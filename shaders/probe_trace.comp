#version 450
// Probe update, trace + shade (probe_update.glsl, shared with gi/probe_update_cpu.cpp): one
// invocation per ray of each probe; id = probe * raysPerProbe + ray. Reads the volume's current
// irradiance (previous frame) for the multi-bounce term. Bindings: 0 volume (one ProbeVolume),
// 1 irradiance atlas (vec4), 2 ray results (vec4), 3 page tables, 4 distance atlas, 5 albedo
// atlas, 6 emission atlas, 7 cascade params (as trace_stack.comp).
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/probe_layout.h"
#include "shaders/shared/color_codec.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Volume { ProbeVolume volume; };
layout(std430, binding = 1) readonly buffer Irradiance { vec4 irradiance[]; };
layout(std430, binding = 2) writeonly buffer Rays { vec4 rays[]; };
layout(std430, binding = 3) readonly buffer PageTable { uint pageTable[]; };
layout(std430, binding = 4) readonly buffer DistanceAtlas { uint distanceAtlas[]; };
layout(std430, binding = 5) readonly buffer AlbedoAtlas { uint albedoAtlas[]; };
layout(std430, binding = 6) readonly buffer EmissionAtlas { uint emissionAtlas[]; };
layout(std430, binding = 7) readonly buffer Cascades { CascadeTraceParams cascades[]; };

layout(push_constant) uniform Push { ProbeUpdatePushConstants pc; };

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#include "shaders/sdf_trace.glsl"
#include "shaders/probe_math.glsl"
#define PROBE_IRRADIANCE(i) irradiance[i]
#include "shaders/probe_update.glsl"

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (id >= pc.counts.y) return;
  uint n = volume.countsRays.w;
  rays[id] = probeTraceRay(volume, pc, id / n, id % n);
}
