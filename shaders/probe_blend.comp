#version 450
// Probe field, blend: a workgroup of 64 per listed probe, for its 232 interior texels (the
// border copies are probe_border.comp, a shader of their own: with this one's shared memory and
// barriers they paid for both; lavapipe ran them at two thirds of the blend's time).
//
// Interior: every texel sums over all the probe's rays (128 by default), so a thread per texel
// reading the rays from the ray buffer loaded 232 x 128 x 32 bytes per probe through L1. The
// workgroup instead stages the rays in shared memory, kBlendRayChunk at a time, each read once
// from the ray buffer, and every thread accumulates its texels (up to 4) chunk by chunk. The
// sums are added in ray order, as probeBlendPass (the CPU reference) adds them.
#extension GL_GOOGLE_include_directive : require
#include "shaders/shared/probe_layout.h"

#define kBlendRayChunk 128u
shared vec4 blendRay[kBlendRayChunk];
shared vec4 blendRayDir[kBlendRayChunk];
uint blendChunkBase;  // the PROBE_RAY index blendRay[0] holds
#define PROBE_RAY(i) blendRay[(i)-blendChunkBase]
#define PROBE_RAY_DIR(i) blendRayDir[(i)-blendChunkBase]
#include "shaders/probe_bindings.glsl"

const uint kTexelsPerThread = (kProbeBlendTexelsPerProbe + kProbeBlendThreadsPerProbe - 1u) /
                              kProbeBlendThreadsPerProbe;

void blendInterior() {
  // One workgroup per probe: l is uniform over it, so the early return keeps the barriers valid.
  uint l = probeInvocation() / kProbeBlendThreadsPerProbe;
  uint lane = gl_LocalInvocationIndex;
  if (l >= probeListLength()) return;
  if (lane == 0u) probeBlendStates(frame, l);
  ProbeBlendTexel texels[kTexelsPerThread];
  vec4 sums[kTexelsPerThread];
  for (uint k = 0u; k < kTexelsPerThread; ++k) {
    uint local = min(lane + k * kProbeBlendThreadsPerProbe, kProbeBlendTexelsPerProbe - 1u);
    texels[k] = probeBlendTexelOf(frame, l, local);
    sums[k] = vec4(0.0f);
  }
  uint n = texels[0].n;
  uint rayBase = texels[0].rayBase;
  for (uint first = 0u; first < n; first += kBlendRayChunk) {
    uint count = min(kBlendRayChunk, n - first);
    barrier();  // the previous chunk is used up
    for (uint r = lane; r < count; r += kProbeBlendThreadsPerProbe) {
      blendRay[r] = PROBE_RAY_STORED(rayBase + first + r);
      blendRayDir[r] = rayDirs[rayBase + first + r];
    }
    barrier();
    blendChunkBase = rayBase + first;
    for (uint k = 0u; k < kTexelsPerThread; ++k)
      if (lane + k * kProbeBlendThreadsPerProbe < kProbeBlendTexelsPerProbe)
        sums[k] = probeBlendAccumulate(frame, texels[k], rayBase + first, count, sums[k]);
  }
  for (uint k = 0u; k < kTexelsPerThread; ++k)
    if (lane + k * kProbeBlendThreadsPerProbe < kProbeBlendTexelsPerProbe)
      probeBlendFinish(frame, texels[k], sums[k]);
}

void main() { blendInterior(); }
