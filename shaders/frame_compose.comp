#version 450
// The picture of a shaded view, composed on the GPU (shared/frame_layout.h): for each pixel the
// probe field's irradiance at its primary hit, sampled through the installable include as an
// engine's shader would (include/sdfstream/probe_sample.glsl), the outgoing radiance direct +
// albedo/π · E_indirect, exposure, the ACES fit and sRGB, packed as RGBA8 (R in the low byte,
// A = 255). Debug modes write the albedo, normals or hit cascade instead. The CPU path it
// replaces (probeQueries, GiSystem::irradiance, composeFrame, toneMap) is its reference.
// Bindings: 0 rays, 1 shaded hits, 2 picture (written), 3-10 the probe field
// (GiSystem::sampleBuffers; with GI off any buffers, never read without kFrameProbesBound),
// 11-18 the moving objects (shaders/object_bindings.glsl; zero instances when none).
#extension GL_GOOGLE_include_directive : require

#define SDFSTREAM_PROBE_BINDING 3
#include "sdfstream/probe_sample.glsl"
#include "shaders/shared/color_codec.h"
#include "shaders/shared/shade_layout.h"
#include "shaders/shared/frame_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Rays { TraceRay rays[]; };
layout(std430, binding = 1) readonly buffer Shaded { ShadedHit shaded[]; };
layout(std430, binding = 2) writeonly buffer Picture { uint picture[]; };

layout(push_constant) uniform Push { FrameComposePush pc; };

#define OBJ_BINDING_BASE 11
#include "shaders/object_bindings.glsl"

// The objects listed in the macro region holding the hit, in the finest region cascade that
// holds it (as objTraceRegions finds it, shaders/object_trace.glsl), as a colour.
uint objectRegionColour(uint id, ShadedHit h) {
  if ((h.flags & kShadeFlagObject) != 0u) return 0xffe6e6e6u;
  if (OBJ_FRAME.counts.x == 0u) return 0xff404040u;  // no objects: no region lists any
  TraceRay r = rays[id];
  vec3 x = r.originTMin.xyz + r.dirTMax.xyz * h.normalT.w;
  for (uint c = 0u; c < OBJ_FRAME.counts.y; ++c) {
    vec4 ro = OBJ_FRAME.regionOrigin[c];
    vec3 q = (x - ro.xyz) / ro.w;
    if (any(lessThan(q, vec3(0.0))) || any(greaterThan(q, vec3(8.0)))) continue;
    ivec3 cell = clamp(ivec3(floor(q)), ivec3(0), ivec3(7));
    uint count = OBJ_REGION(c * 512u + uint(cell.x) + 8u * (uint(cell.y) + 8u * uint(cell.z))).count;
    return count == 0u ? 0xff404040u : count == 1u ? 0xff3cdce6u : count < 4u ? 0xff28a0f0u
                                                                              : 0xff3c3ce6u;
  }
  return 0xff000000u;
}

// One colour per cascade (as the viewer's legend): red, orange, yellow, green, cyan, blue,
// violet, white.
const uint kCascadeColours[8] = uint[8](0x3c3ce6u, 0x28a0f0u, 0x3cdce6u, 0x50c850u, 0xdcc83cu,
                                        0xf06e46u, 0xe65aaau, 0xe6e6e6u);

uint packPicture(vec3 linear) {
  vec3 c = frameAcesFitted(linear * pc.params.x);
  return frameSrgb8(c.x) | (frameSrgb8(c.y) << 8) | (frameSrgb8(c.z) << 16) | 0xff000000u;
}

// The state of the probe nearest the hit in the finest volume that holds it (the probe field's
// own grid math, shaders/probe_field.glsl), as a colour.
uint probeStateColour(uint id, ShadedHit h) {
  const uint kStateColours[4] = uint[4](0xff505050u, 0xffe6a03cu, 0xff50c850u, 0xff3c3ce6u);
  TraceRay r = rays[id];
  vec3 x = r.originTMin.xyz + r.dirTMax.xyz * h.normalT.w + h.normalT.xyz * h.direct.w;
  for (uint c = 0u; c < sdfstreamProbeFrame.counts.x; ++c) {
    ProbeVolume v = sdfstreamProbeVolumes[c];
    vec3 g = (x - v.originSpacing.xyz) / v.originSpacing.w;
    vec3 last = vec3(v.countsRays.xyz) - 1.0;
    if (any(lessThan(g, vec3(0.0))) || any(greaterThan(g, last))) continue;
    uint s = probeStorageIndex(v, ivec3(floor(g + 0.5)));
    uint state = probeStateOf(sdfstreamProbeData[c * sdfstreamProbeFrame.counts.y + s]);
    return kStateColours[min(state, 3u)];
  }
  return 0xff000000u;
}

void main() {
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
  if (id >= pc.size.x * pc.size.y) return;
  ShadedHit h = shaded[id];
  bool hit = (h.flags & kHitFlagHit) != 0u;
  uint mode = pc.size.z;
  if (mode == kFrameResidency) {
    uint c = 0xff000000u;
    if (hit) c = (h.flags & kHitFlagFellBack) != 0u ? 0xff1e8cf0u : 0xff50c850u;
    else if ((h.flags & kHitFlagMissingData) != 0u) c = 0xff3c3ce6u;
    picture[id] = c;
    return;
  }
  if (mode == kFrameObjectRegions) {
    picture[id] = hit ? objectRegionColour(id, h) : 0xff000000u;
    return;
  }
  if (mode == kFrameProbeStates) {
    picture[id] = hit && (pc.size.w & kFrameProbesBound) != 0u ? probeStateColour(id, h)
                                                               : 0xff000000u;
    return;
  }
  if (mode >= kFrameAlbedo) {
    uint c = 0xff000000u;
    if (hit && mode == kFrameAlbedo) c = (h.albedo & 0x00ffffffu) | 0xff000000u;
    if (hit && mode == kFrameNormals) {
      vec3 n = clamp(h.normalT.xyz * 0.5 + 0.5, 0.0, 1.0);
      uvec3 b = uvec3(n * 255.0 + 0.5);
      c = b.x | (b.y << 8) | (b.z << 16) | 0xff000000u;
    }
    if (hit && mode == kFrameCascade)
      c = kCascadeColours[(h.flags >> kHitCascadeShift) & 7u] | 0xff000000u;
    picture[id] = c;
    return;
  }
  vec3 direct = h.direct.xyz;
  vec3 indirect = vec3(0.0);
  bool probes = (pc.size.w & kFrameProbesBound) != 0u;
  bool wantIndirect =
      mode == kFrameIndirect || (mode == kFrameFinal && (pc.size.w & kFrameAddIndirect) != 0u);
  if (hit && probes && wantIndirect) {
    // The probe query of probeQueries (demo/gi_shading.cpp): the hit point, moved out along the
    // normal as far as the shading pass started its shadow rays (direct.w), viewed from the ray.
    TraceRay r = rays[id];
    vec3 n = h.normalT.xyz;
    vec3 x = r.originTMin.xyz + r.dirTMax.xyz * h.normalT.w + n * h.direct.w;
    vec3 e = sdfstreamIrradiance(x, n, -r.dirTMax.xyz);
    vec4 a = unpackAlbedo(h.albedo);
    vec3 albedo = vec3(frameSrgbToLinear(a.x), frameSrgbToLinear(a.y), frameSrgbToLinear(a.z));
    indirect = albedo * 0.3183098861837907 * e;
  }
  vec3 radiance = mode == kFrameDirect     ? direct
                  : mode == kFrameIndirect ? indirect * pc.params.y
                                           : direct + indirect;
  picture[id] = packPicture(radiance);
}
