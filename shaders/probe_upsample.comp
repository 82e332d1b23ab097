#version 450
// Reduced-resolution sampling's second pass: every full-resolution pixel's irradiance from the
// low-resolution samples probe_sample.comp took (probeUpsampleBlockPixel, probe_upsample.glsl),
// one invocation per pixel, row by row. results rgb = irradiance, a = 0.
#extension GL_GOOGLE_include_directive : require
#include "shaders/shared/probe_layout.h"

layout(std430, binding = 0) readonly buffer Queries { ProbeQuery queries[]; };
layout(std430, binding = 1) readonly buffer LowResolution { vec4 lowResolution[]; };
layout(std430, binding = 2) writeonly buffer Results { vec4 results[]; };
// dispatch: x = block size (2 or 4), y = pixels, z = width, w = height.
layout(push_constant) uniform Push { ProbePushConstants pc; };
layout(local_size_x = 64) in;

#define PROBE_UPSAMPLE_QUERY(i) queries[i]
#define PROBE_UPSAMPLE_LOW(i) lowResolution[i]
#include "shaders/probe_upsample.glsl"

void main() {
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
  if (id >= pc.dispatch.y) return;
  uint width = pc.dispatch.z;
  results[id] =
      vec4(probeUpsampleBlockPixel(id % width, id / width, pc.dispatch.x, width, pc.dispatch.w), 0.0);
}
