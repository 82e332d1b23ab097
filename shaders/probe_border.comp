#version 450
// Probe field, border copies (M21 Sec. 3, the octahedral tiles' one-texel border): one invocation
// per tile texel of each listed probe (320), after probe_blend.comp wrote the interiors.
#extension GL_GOOGLE_include_directive : require
#include "shaders/probe_bindings.glsl"

void main() {
  uint id = probeInvocation();
  uint l = id / kProbeTileTexelsPerProbe;
  if (id >= pc.dispatch.y || l >= probeListLength()) return;
  probeBorderPass(l, id % kProbeTileTexelsPerProbe);
}
