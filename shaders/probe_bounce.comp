#version 450
// Probe field, bounce cells (probe_trace.glsl, "Bounce cells"), after the trace pass: mode
// kProbeBounceModeCells looks up the cells the trace listed, then kProbeBounceModeRays adds the
// multi-bounce term to the rays that waited for them and lists those whose cell disagrees, then
// kProbeBounceModeOwn looks those up at their own hits. Dispatched like the trace (one thread per
// listed ray, an upper bound on every list); threads past a list's length return.
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint id = probeInvocation();
  if (id >= pc.dispatch.y) return;
  if (pc.dispatch.x == kProbeBounceModeCells) {
    if (id < stats[kProbeStatBounceCells]) probeBounceCellPass(frame, id);
  } else if (pc.dispatch.x == kProbeBounceModeRays) {
    if (id < stats[kProbeStatBounceRays]) probeBounceRayPass(frame, id);
  } else if (id < stats[kProbeStatBounceOwn]) {
    probeBounceOwnPass(frame, id);
  }
}
