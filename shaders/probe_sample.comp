#version 450
// Batched irradiance queries of one probe volume (probeSampleVolume in probe_update.glsl, shared
// with gi/probe_update_cpu.cpp): one invocation per query. Bindings: 0 volume, 1 irradiance atlas
// (vec4), 2 depth atlas (vec2), 3 queries (ProbeQuery), 4 results (vec4: rgb irradiance, a 0).
// Push constants: ProbeUpdatePushConstants, counts.y = query count.
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/probe_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Volume { ProbeVolume volume; };
layout(std430, binding = 1) readonly buffer Irradiance { vec4 irradiance[]; };
layout(std430, binding = 2) readonly buffer Depth { vec2 depth[]; };
layout(std430, binding = 3) readonly buffer Queries { ProbeQuery queries[]; };
layout(std430, binding = 4) writeonly buffer Results { vec4 results[]; };

layout(push_constant) uniform Push { ProbeUpdatePushConstants pc; };

#include "shaders/probe_math.glsl"
#define PROBE_IRRADIANCE(i) irradiance[i]
#define PROBE_DEPTH(i) depth[i]
#include "shaders/probe_update.glsl"

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (id >= pc.counts.y) return;
  ProbeQuery q = queries[id];
  results[id] = vec4(probeSampleVolume(volume, vec3(q.position), vec3(q.normal), vec3(q.view)), 0.0);
}
