// The probe update of one probe volume (issue 5 item 2): per probe ray trace + shade, per texel
// blend. Single definition: probe_trace.comp / probe_blend.comp include it as GLSL and
// gi/probe_update_cpu.cpp includes it as C++ inside a struct (the CPU reference, STYLE.md habit
// 9), like sdf_trace.glsl and probe_math.glsl. Same rules: no swizzles, no out parameters,
// f-suffixed float literals.
//
// The includer first includes shaders/shared/{sdf_layout,probe_layout,color_codec}.h,
// shaders/sdf_trace.glsl (with SDF_CASCADE defined) and shaders/probe_math.glsl, and defines
//   PROBE_IRRADIANCE(i) -> vec4 stored irradiance texel i (probeIrradianceIndex)
//   PROBE_DEPTH(i)      -> vec2 stored depth texel i (sampling functions only)
//   PROBE_RAY(i)        -> vec4 ray result i = probe * raysPerProbe + ray (blend functions only;
//                          the trace function needs sdf_trace.glsl's SDF_CASCADE instead)
//
// Storage (storage buffers, no images):
//   irradiance atlas: probe-major, 8x8 tile texels per probe (probe_layout.h), vec4 each:
//     rgb = irradiance^(1/gamma) (perceptual encoding), a = 1 once the texel was ever written;
//   depth atlas: probe-major, 16x16 tile texels per probe, vec2 = (mean, mean²) of ray depth;
//   ray buffer: vec4 per ray, rgb = radiance (linear), a = depth (probeRayDepth), both in
//     cascade-0 voxels (not probe spacings), like every distance handed to the GPU.
// Probe p sits at grid coordinate (p % nx, p / nx % ny, p / (nx ny)) (no scrolling yet: the
// volume's scroll field is ignored), at originSpacing.xyz + coordinate * spacing.

#ifndef PROBE_IRRADIANCE
#error "define PROBE_IRRADIANCE(i) before including probe_update.glsl"
#endif

uint probeIrradianceIndex(uint probe, uvec2 tileTexel) {
  return probe * (kProbeIrradianceTexels * kProbeIrradianceTexels) +
         tileTexel.y * kProbeIrradianceTexels + tileTexel.x;
}

uint probeDepthIndex(uint probe, uvec2 tileTexel) {
  return probe * (kProbeDepthTexels * kProbeDepthTexels) + tileTexel.y * kProbeDepthTexels +
         tileTexel.x;
}

mat3 probeVolumeRotation(ProbeVolume v) {
  return mat3(vec3(v.rayRotationCol0), vec3(v.rayRotationCol1), vec3(v.rayRotationCol2));
}

vec3 probePosition(ProbeVolume v, uint probe) {
  uint nx = v.countsRays.x;
  uint ny = v.countsRays.y;
  vec3 coord = vec3(float(probe % nx), float((probe / nx) % ny), float(probe / (nx * ny)));
  return vec3(v.originSpacing) + coord * v.originSpacing.w;
}

// The probe whose grid point is nearest to p (clamped to the grid).
uint probeNearest(ProbeVolume v, vec3 p) {
  vec3 g = floor((p - vec3(v.originSpacing)) / v.originSpacing.w + vec3(0.5f));
  int x = clamp(int(g.x), 0, int(v.countsRays.x) - 1);
  int y = clamp(int(g.y), 0, int(v.countsRays.y) - 1);
  int z = clamp(int(g.z), 0, int(v.countsRays.z) - 1);
  return uint(x) + v.countsRays.x * (uint(y) + v.countsRays.y * uint(z));
}

// Bilinear read of a probe's irradiance tile in direction d, as a GPU sampler filters the
// bordered tile (encoded values filtered, then decoded); the same lookup as
// ProbeTexels::sampleIrradiance. Needs the borders filled.
vec3 probeSampleIrradiance(uint probe, vec3 d, float gamma) {
  vec2 c = probeTileCoord(d, kProbeIrradianceInterior) - vec2(0.5f);
  vec2 base = floor(c);
  vec2 f = c - base;
  int last = int(kProbeIrradianceTexels) - 1;
  uint x0 = uint(clamp(int(base.x), 0, last));
  uint y0 = uint(clamp(int(base.y), 0, last));
  uint x1 = min(x0 + 1u, uint(last));
  uint y1 = min(y0 + 1u, uint(last));
  vec3 a = mix(vec3(PROBE_IRRADIANCE(probeIrradianceIndex(probe, uvec2(x0, y0)))),
               vec3(PROBE_IRRADIANCE(probeIrradianceIndex(probe, uvec2(x1, y0)))), f.x);
  vec3 b = mix(vec3(PROBE_IRRADIANCE(probeIrradianceIndex(probe, uvec2(x0, y1)))),
               vec3(PROBE_IRRADIANCE(probeIrradianceIndex(probe, uvec2(x1, y1)))), f.x);
  return probeDecodeIrradiance(mix(a, b, f.y), gamma);
}

float probeSrgbChannelToLinear(float c) {
  return c <= 0.04045f ? c * (1.0f / 12.92f) : pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

vec3 probeSrgbToLinear(vec3 c) {
  return vec3(probeSrgbChannelToLinear(c.x), probeSrgbChannelToLinear(c.y),
              probeSrgbChannelToLinear(c.z));
}

#ifdef SDF_CASCADE
// Trace and shade ray `ray` of probe `probe`. Returns (radiance rgb, depth), see the header.
//  - miss (left the stack, or out of steps): sky radiance, depth = v.blend.z (max depth);
//  - backface hit (SDF gradient along the ray: the probe sits inside geometry): radiance 0,
//    depth shortened (probeRayDepth) so visibility treats it as a near occluder (M21 Sec. 4.1);
//  - front hit: Lambertian exit radiance  L = emission + albedo * gain * E(n) / pi,  with E(n)
//    this volume's current (previous frame's) irradiance of the probe nearest to the hit in the
//    direction of the hit normal: multi-bounce feedback with bounce gain (issue 5 item 5).
//    Direct light is not shaded yet (no light cache): emission and sky only.
vec4 probeTraceRay(ProbeVolume v, ProbeUpdatePushConstants pc, uint probe, uint ray) {
  uint n = v.countsRays.w;
  vec3 dir = probeRayDirection(ray, n, probeVolumeRotation(v));
  vec3 origin = probePosition(v, probe);
  SdfStackResult s = sdfTraceStack(origin, dir, 0.0f, pc.trace.y, pc.counts.z, pc.trace.x,
                                   pc.counts.w);
  float maxDepth = v.blend.z;
  if (!s.r.hit) return vec4(vec3(pc.skyBounce), maxDepth);
  vec3 normal = sdfNormal(s.r.position, SDF_CASCADE(s.cascade).toroidal);
  bool backface = dot(normal, dir) > 0.0f;
  float depth = probeRayDepth(s.t0, true, backface, maxDepth, v.visibility.z);
  if (backface) return vec4(0.0f, 0.0f, 0.0f, depth);
  uint m = s.r.slot * kBrickMaterialCount + s.r.cell;
  vec3 albedo = probeSrgbToLinear(vec3(unpackAlbedo(SDF_ALBEDO(m))));
  vec3 emission = unpackRgb9e5(SDF_EMISSION(m));
  uint nearest = probeNearest(v, origin + dir * s.t0);
  vec3 irradiance = probeSampleIrradiance(nearest, normal, v.blend.w);
  return vec4(emission + albedo * irradiance * (pc.skyBounce.w * 0.3183098861837907f), depth);
}

#endif  // SDF_CASCADE

#ifdef PROBE_RAY
// Hysteresis of this update: 0 the first time (a reset probe takes the fresh estimate at once),
// otherwise the volume's, lowered per texel by the change heuristic when asked (M21 Sec. 4.3).
float probeTexelHysteresis(float hysteresis, bool firstUpdate) {
  return firstUpdate ? 0.0f : hysteresis;
}

// New stored value of interior irradiance texel `texel` (0..5 per axis) of `probe`: cosine-
// weighted mean of this frame's rays (probeIrradianceFromSums), encoded with gamma, blended with
// the old stored value in encoded space (M21 Eq. 1, Sec. 4.2). No weighted ray: unchanged.
vec4 probeBlendIrradianceTexel(ProbeVolume v, uint probe, uvec2 texel, vec4 oldStored,
                               bool adaptive, bool firstUpdate) {
  uint n = v.countsRays.w;
  mat3 rotation = probeVolumeRotation(v);
  vec3 texelDir = probeTexelDirection(texel, kProbeIrradianceInterior);
  vec4 sums = vec4(0.0f);
  for (uint r = 0u; r < n; ++r) {
    vec4 result = PROBE_RAY(probe * n + r);
    float w = probeIrradianceWeight(texelDir, probeRayDirection(r, n, rotation));
    sums += vec4(vec3(result) * w, w);
  }
  if (sums.w <= 0.0f) return oldStored;
  vec3 fresh = probeEncodeIrradiance(probeIrradianceFromSums(sums), v.blend.w);
  vec3 old = vec3(oldStored);
  float h = probeTexelHysteresis(v.blend.x, firstUpdate || oldStored.w == 0.0f);
  if (adaptive && h > 0.0f) h = probeAdjustHysteresis(old, fresh, h);
  return vec4(probeHysteresisBlend3(old, fresh, h), 1.0f);
}

// New stored (mean, mean²) of interior depth texel `texel` (0..13 per axis): power-cosine
// weighted (sharpness v.visibility.y) moments of the ray depths, blended with hysteresis.
vec2 probeBlendDepthTexel(ProbeVolume v, uint probe, uvec2 texel, vec2 oldStored,
                          bool firstUpdate) {
  uint n = v.countsRays.w;
  mat3 rotation = probeVolumeRotation(v);
  vec3 texelDir = probeTexelDirection(texel, kProbeDepthInterior);
  vec3 sums = vec3(0.0f);  // w d, w d², w
  for (uint r = 0u; r < n; ++r) {
    float d = PROBE_RAY(probe * n + r).w;
    float w = probeDepthWeight(texelDir, probeRayDirection(r, n, rotation), v.visibility.y);
    sums += vec3(w * d, w * d * d, w);
  }
  if (sums.z <= 0.0f) return oldStored;
  vec2 fresh = vec2(sums.x / sums.z, sums.y / sums.z);
  return probeHysteresisBlend2(oldStored, fresh, probeTexelHysteresis(v.blend.y, firstUpdate));
}
#endif  // PROBE_RAY

#ifdef PROBE_DEPTH
// Bilinear read of a probe's depth-moment tile in direction d (as ProbeTexels::sampleDepth).
vec2 probeSampleDepth(uint probe, vec3 d) {
  vec2 c = probeTileCoord(d, kProbeDepthInterior) - vec2(0.5f);
  vec2 base = floor(c);
  vec2 f = c - base;
  int last = int(kProbeDepthTexels) - 1;
  uint x0 = uint(clamp(int(base.x), 0, last));
  uint y0 = uint(clamp(int(base.y), 0, last));
  uint x1 = min(x0 + 1u, uint(last));
  uint y1 = min(y0 + 1u, uint(last));
  vec2 a = mix(PROBE_DEPTH(probeDepthIndex(probe, uvec2(x0, y0))),
               PROBE_DEPTH(probeDepthIndex(probe, uvec2(x1, y0))), f.x);
  vec2 b = mix(PROBE_DEPTH(probeDepthIndex(probe, uvec2(x0, y1))),
               PROBE_DEPTH(probeDepthIndex(probe, uvec2(x1, y1))), f.x);
  return mix(a, b, f.y);
}

// irradiance(x, n, view) of one volume (M21 Sec. 2.2 and 4.1; H22 Sec. 4.4): the 8 probes of the
// cage around the biased receiver x + probeSelfShadowBias(n, view, spacing, B), each weighted by
// backface (wrap) weight x Chebyshev visibility (depth moments towards the biased receiver),
// crushed below 0.2 (probeCrushWeight), x trilinear weight; the weighted mean of the probes'
// decoded irradiance in direction n. Receivers outside the grid clamp to its border cage.
// Units: cascade-0 voxels. Returns 0 when every weight vanishes (cannot happen: backface >= 0.2
// and Chebyshev > 0, but a cage corner with trilinear weight 0 contributes nothing).
vec3 probeSampleVolume(ProbeVolume v, vec3 x, vec3 n, vec3 view) {
  float spacing = v.originSpacing.w;
  vec3 origin = vec3(v.originSpacing);
  vec3 biased = x + probeSelfShadowBias(n, view, spacing, v.visibility.x);
  vec3 g = (biased - origin) / spacing;
  ivec3 maxBase = ivec3(max(int(v.countsRays.x) - 2, 0), max(int(v.countsRays.y) - 2, 0),
                        max(int(v.countsRays.z) - 2, 0));
  ivec3 base = clamp(ivec3(floor(g)), ivec3(0), maxBase);
  vec3 alpha = clamp(g - vec3(base), vec3(0.0f), vec3(1.0f));
  vec3 sum = vec3(0.0f);
  float sumW = 0.0f;
  for (uint corner = 0u; corner < 8u; ++corner) {
    ivec3 c = base + ivec3(int(corner & 1u), int((corner >> 1u) & 1u), int((corner >> 2u) & 1u));
    c = min(c, ivec3(int(v.countsRays.x) - 1, int(v.countsRays.y) - 1, int(v.countsRays.z) - 1));
    uint probe = uint(c.x) + v.countsRays.x * (uint(c.y) + v.countsRays.y * uint(c.z));
    vec3 p = origin + vec3(c) * spacing;
    vec3 toProbe = p - x;
    float lenToProbe = length(toProbe);
    vec3 dirToProbe = lenToProbe > 1e-6f ? toProbe / lenToProbe : n;
    float w = probeBackfaceWeight(dirToProbe, n);
    vec3 fromProbe = biased - p;
    float r = length(fromProbe);
    vec3 dirFromProbe = r > 1e-6f ? fromProbe / r : n;
    w *= probeChebyshevWeight(probeSampleDepth(probe, dirFromProbe), r, v.visibility.w);
    w = probeCrushWeight(max(w, 1e-6f), 0.2f);
    w *= probeTrilinearWeight(alpha, corner);
    sum += probeSampleIrradiance(probe, n, v.blend.w) * w;
    sumW += w;
  }
  return sumW > 0.0f ? sum / sumW : vec3(0.0f);
}
#endif  // PROBE_DEPTH
