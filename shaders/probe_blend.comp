#version 450
// Probe update, blend (probe_update.glsl, shared with gi/probe_update_cpu.cpp). Two modes
// (pc.mode.x), dispatched one after the other:
//  - kProbeBlendModeInterior: one invocation per interior texel, id = probe * 232 + local;
//    local < 36: irradiance texel (local % 6, local / 6), else depth texel ((local-36) % 14, /14).
//  - kProbeBlendModeBorder: one invocation per tile texel, id = probe * 320 + local; local < 64:
//    irradiance tile texel, else depth tile texel; border texels copy probeBorderSource.
// Bindings: 0 volume, 1 irradiance atlas (vec4), 2 depth atlas (vec2), 3 ray results (vec4).
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/probe_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Volume { ProbeVolume volume; };
layout(std430, binding = 1) buffer Irradiance { vec4 irradiance[]; };
layout(std430, binding = 2) buffer Depth { vec2 depth[]; };
layout(std430, binding = 3) readonly buffer Rays { vec4 rays[]; };

layout(push_constant) uniform Push { ProbeUpdatePushConstants pc; };

#include "shaders/probe_math.glsl"
#define PROBE_IRRADIANCE(i) irradiance[i]
#define PROBE_RAY(i) rays[i]
#include "shaders/probe_update.glsl"

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (id >= pc.counts.y) return;
  bool firstUpdate = pc.trace.w != 0.0;
  const uint irrCount = kProbeIrradianceInterior * kProbeIrradianceInterior;
  const uint irrTile = kProbeIrradianceTexels * kProbeIrradianceTexels;
  if (pc.mode.x == kProbeBlendModeInterior) {
    uint probe = id / kProbeBlendTexelsPerProbe;
    uint local = id % kProbeBlendTexelsPerProbe;
    if (local < irrCount) {
      uvec2 texel = uvec2(local % kProbeIrradianceInterior, local / kProbeIrradianceInterior);
      uint i = probeIrradianceIndex(probe, texel + uvec2(kProbeBorderTexels));
      irradiance[i] = probeBlendIrradianceTexel(volume, probe, texel, irradiance[i],
                                                pc.trace.z != 0.0, firstUpdate);
    } else {
      local -= irrCount;
      uvec2 texel = uvec2(local % kProbeDepthInterior, local / kProbeDepthInterior);
      uint i = probeDepthIndex(probe, texel + uvec2(kProbeBorderTexels));
      depth[i] = probeBlendDepthTexel(volume, probe, texel, depth[i], firstUpdate);
    }
  } else {
    uint probe = id / kProbeTileTexelsPerProbe;
    uint local = id % kProbeTileTexelsPerProbe;
    if (local < irrTile) {
      uvec2 t = uvec2(local % kProbeIrradianceTexels, local / kProbeIrradianceTexels);
      uvec2 s = probeBorderSource(t, kProbeIrradianceTexels);
      if (s != t) irradiance[probeIrradianceIndex(probe, t)] = irradiance[probeIrradianceIndex(probe, s)];
    } else {
      local -= irrTile;
      uvec2 t = uvec2(local % kProbeDepthTexels, local / kProbeDepthTexels);
      uvec2 s = probeBorderSource(t, kProbeDepthTexels);
      if (s != t) depth[probeDepthIndex(probe, t)] = depth[probeDepthIndex(probe, s)];
    }
  }
}
