#version 450
// Probe field, hit-cache check: one invocation per hit-cache entry of every probe
// (probeCacheCheckPass), dispatched only when a window scrolled or pages changed.
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint i = probeInvocation();
  if (i < pc.dispatch.y) probeCacheCheckPass(frame, i);
}
