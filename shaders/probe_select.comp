#version 450
// Probe field, select: one invocation per probe; pc.dispatch.x = kProbeSelectModeCount (count
// wanted probes per priority class), kProbeSelectModeEmit (append those below the cutoff), then
// kProbeSelectModeArgs (one invocation: the group counts of trace / blend / border).
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint g = probeInvocation();
  if (pc.dispatch.x == kProbeSelectModeArgs) {
    if (g == 0u) probeWriteListDispatches(frame, volumes[0].countsRays.w);
  } else if (g < pc.dispatch.y) {
    probeSelectPass(frame, g, pc.dispatch.x);
  }
}
