#version 450
// Probe field, trace + shade: one invocation per ray of each listed probe (list capacity x rays
// are dispatched; threads past the list's length return).
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint id = probeInvocation();
  uint n = volumes[0].countsRays.w;  // every volume has the same rays per probe
  uint l = id / n;
  if (id >= pc.dispatch.y || l >= probeListLength()) return;
  probeTracePass(frame, l, id % n);
}
