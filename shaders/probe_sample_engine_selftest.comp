#version 450
// An engine's shader sampling the probe field through the installable include, the way an
// engine would: its own buffers at bindings 0-2 (2 unused here), the field's eight from
// SDFSTREAM_PROBE_BINDING = 3 on. One irradiance query per invocation; push x = queries, y = 1
// when the positions are world metres (sdfstreamIrradianceWorld), else the field's own
// coordinates (sdfstreamIrradiance). tests/probes/probe_sample_include_test.cpp compares the
// results with ProbeField::sample; tests/probes/check_installed_glsl.cmake compiles it against
// the installed include alone.
#extension GL_GOOGLE_include_directive : require

#define SDFSTREAM_PROBE_BINDING 3
#include "sdfstream/probe_sample.glsl"

layout(std430, binding = 0) readonly buffer EngineQueries { ProbeQuery engineQueries[]; };
layout(std430, binding = 1) writeonly buffer EngineResults { vec4 engineResults[]; };
layout(push_constant) uniform EnginePush { uvec4 enginePush; };

layout(local_size_x = 64) in;

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (id >= enginePush.x) return;
  ProbeQuery q = engineQueries[id];
  vec3 e = enginePush.y != 0u ? sdfstreamIrradianceWorld(q.position.xyz, q.normal.xyz, q.view.xyz)
                              : sdfstreamIrradiance(q.position.xyz, q.normal.xyz, q.view.xyz);
  engineResults[id] = vec4(e, 0.0);
}
