#version 450
// Batched irradiance(x, n, view) queries of the probe field (probeFieldIrradiance): one
// invocation per query (position.w = 1 + cascade samples that cascade alone, 0 = all);
// results rgb = irradiance, a = 0.
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint id = probeInvocation();
  if (id >= pc.dispatch.y) return;
  ProbeQuery q = queries[id];
  results[id] = vec4(probeFieldIrradiance(frame, q.position.xyz, q.normal.xyz, q.view.xyz, true,
                                          int(q.position.w) - 1), 0.0);
}
