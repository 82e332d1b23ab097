#version 450
// Probe field, blend: pc.dispatch.x = kProbeBlendModeInterior (one invocation per interior texel
// of each listed probe, 232 per probe) or kProbeBlendModeBorder (one per tile texel, 320).
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint id = probeInvocation();
  bool interior = pc.dispatch.x == kProbeBlendModeInterior;
  uint perProbe = interior ? kProbeBlendTexelsPerProbe : kProbeTileTexelsPerProbe;
  uint l = id / perProbe;
  if (id >= pc.dispatch.y || l >= probeListLength()) return;
  if (interior)
    probeBlendPass(frame, l, id % perProbe);
  else
    probeBorderPass(l, id % perProbe);
}
