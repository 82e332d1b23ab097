#version 450
// Probe field, select: one invocation per probe; pc.dispatch.x = kProbeSelectModeCount (count
// wanted probes per priority class) then kProbeSelectModeEmit (append those below the cutoff).
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint g = probeInvocation();
  if (g < pc.dispatch.y) probeSelectPass(frame, g, pc.dispatch.x);
}
