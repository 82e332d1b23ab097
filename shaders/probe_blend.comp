#version 450
// Probe field, blend: a workgroup of 64 per listed probe, for its 260 interior texels, each
// written with its border copies (probeBlendFinish; no pass of their own, no barrier).
//
// Interior: every texel sums over all the probe's rays (128 by default), so a thread per texel
// reading the rays from the ray buffer loaded 232 x 128 x 32 bytes per probe through L1. The
// workgroup instead stages the rays in shared memory, kBlendRayChunk at a time, each read once
// from the ray buffer, and every thread accumulates its texels (up to 4) one after the other. The
// sums are added in ray order, as probeBlendPass (the CPU reference) adds them. A depth texel reads
// only the rays its list names (probe_update.glsl, probeDepthTexelSumsListed): ~13 instead of 128,
// each with its weight from the list instead of a pow.
#extension GL_GOOGLE_include_directive : require
#include "shaders/shared/probe_layout.h"

#define kBlendRayChunk 128u
shared vec4 blendRay[kBlendRayChunk];
shared vec4 blendRayDir[kBlendRayChunk];
shared uint blendBackfaces;  // the probe's rays that hit a backface (probeBlendStatesFromCount)
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
  // The backfaces are counted by every lane as it stages the rays (lane 0 alone, one ray after
  // the other, kept the others waiting at the first barrier).
  bool states = (frame.options.x & kProbeOptionStates) != 0u;
  if (lane == 0u) blendBackfaces = 0u;
  uint backfaces = 0u;
  // A texel at a time, its sums in registers (arrays of the thread's texels were kept in local
  // memory by the driver, 288 bytes a thread; unrolling them instead cost occupancy: 96
  // registers, blend +9% on the H100). When the probe's rays fit one chunk, they are staged once
  // and every texel reads them from there.
  for (uint k = 0u; k < kTexelsPerThread; ++k) {
    uint local = lane + k * kProbeBlendThreadsPerProbe;
    bool has = local < kProbeBlendTexelsPerProbe;
    ProbeBlendTexel t = probeBlendTexelOf(frame, l, min(local, kProbeBlendTexelsPerProbe - 1u));
    uint n = t.n;
    uint rayBase = t.rayBase;
    vec4 sums = vec4(0.0f);
    for (uint first = 0u; first < n; first += kBlendRayChunk) {
      uint count = min(kBlendRayChunk, n - first);
      if (k == 0u || n > kBlendRayChunk) {  // uniform over the workgroup: one probe's n
        barrier();  // the previous chunk is used up
        for (uint r = lane; r < count; r += kProbeBlendThreadsPerProbe) {
          blendRay[r] = PROBE_RAY_STORED(rayBase + first + r);
          blendRayDir[r] = rayDirs[rayBase + first + r];
          if (k == 0u && blendRay[r].w < 0.0f) ++backfaces;
        }
        barrier();
      }
      blendChunkBase = rayBase + first;
      if (has) sums = probeBlendAccumulate(frame, t, rayBase + first, count, sums);
    }
    if (has) probeBlendFinish(frame, t, sums);
  }
  if (states) {  // uniform over the workgroup
    uint total = subgroupAdd(backfaces);
    if (subgroupElect()) atomicAdd(blendBackfaces, total);
    barrier();
    if (lane == 0u) probeBlendStatesFromCount(frame, l, blendBackfaces);
  }
}

void main() { blendInterior(); }
