#version 460
// Evaluates shaders/probe_math.glsl on the GPU for tests/probes (probe_gpu_test.cpp compares it
// with the same functions compiled as C++). Also keeps probe_math.glsl compiled as GLSL at build
// time (STYLE.md habit 10). Bindings: 0 inputs (2 vec4 per item), 1 outputs (4 vec4 per item).
//   in[2i]   xyz: a unit direction            in[2i+1] xy: an octahedral coordinate, z: distance
//   out[4i]   xyz: ray direction i of rayCount (rotated)
//   out[4i+1] xy: probeOctEncode(in dir), zw: probeTileCoord(in dir, 6)
//   out[4i+2] xyz: probeOctDecode(in oct)
//   out[4i+3] xy: probeBorderSource(texel i mod 64 of an 8x8 tile), z: Chebyshev weight of the
//             distance for moments (4, 17), w: probeBackfaceWeight(in dir, +z)
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/probe_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 outputs[]; };

layout(push_constant) uniform Push {
  vec4 rotationCol0;
  vec4 rotationCol1;
  vec4 rotationCol2;
  uvec4 counts;  // x: items, y: rays per probe
} pc;

#include "shaders/probe_math.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.counts.x) return;
  mat3 rotation = mat3(pc.rotationCol0.xyz, pc.rotationCol1.xyz, pc.rotationCol2.xyz);
  vec3 dir = inputs[2u * i].xyz;
  vec4 other = inputs[2u * i + 1u];
  outputs[4u * i] = vec4(probeRayDirection(i % pc.counts.y, pc.counts.y, rotation), 0.0f);
  outputs[4u * i + 1u] = vec4(probeOctEncode(dir), probeTileCoord(dir, kProbeIrradianceInterior));
  outputs[4u * i + 2u] = vec4(probeOctDecode(other.xy), 0.0f);
  uint t = i % (kProbeIrradianceTexels * kProbeIrradianceTexels);
  uvec2 src = probeBorderSource(uvec2(t % kProbeIrradianceTexels, t / kProbeIrradianceTexels),
                                kProbeIrradianceTexels);
  outputs[4u * i + 3u] = vec4(float(src.x), float(src.y),
                              probeChebyshevWeight(vec2(4.0f, 17.0f), other.z, kProbeMinVariance),
                              probeBackfaceWeight(dir, vec3(0.0f, 0.0f, 1.0f)));
}
