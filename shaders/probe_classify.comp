#version 450
// Probe field, classify: one invocation per probe of every volume (probeClassifyPass).
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint g = probeInvocation();
  if (g < pc.dispatch.y) probeClassifyPass(frame, g);
}
