// Per-probe texel math of the probe update: blending one update's rays into the
// octahedral texels, and bilinear tile reads. Single definition: the probe passes include it as
// GLSL and gi/probe_field_cpu.cpp includes it as C++ inside a struct (the CPU reference, STYLE.md
// habit 9), like sdf_trace.glsl and probe_math.glsl. Same rules: no swizzles, no out parameters,
// f-suffixed float literals. The field-level logic (cascades, scheduling, tracing, sampling) is
// shaders/probe_field.glsl and the pass files it lists.
//
// The includer first includes shaders/shared/{sdf_layout,probe_layout,color_codec}.h and
// shaders/probe_math.glsl, and defines
//   PROBE_IRRADIANCE(i) -> vec4 stored irradiance texel i (probeIrradianceIndex)
//   PROBE_DEPTH(i)      -> vec2 stored depth texel i (sampling functions only)
//   PROBE_RAY(i)        -> vec4 ray result i (blend functions only): rays of the probe at
//                          position l of this frame's update list are l * raysPerProbe + ray
//   PROBE_RAY_DIR(i)    -> vec4 direction (xyz) of ray result i
//
// Storage (storage buffers, no images):
//   irradiance atlas: probe-major, 8x8 tile texels per probe (probe_layout.h), vec4 each:
//     rgb = irradiance^(1/gamma) (perceptual encoding), a = 1 once the texel was ever written;
//   depth atlas: probe-major, 16x16 tile texels per probe, vec2 = (mean, mean²) of ray depth;
//   ray buffer: vec4 per ray, rgb = radiance (linear), a = depth (probeRayDepth), both in
//     cascade-0 voxels (not probe spacings), like every distance handed to the GPU.
// Probe indices here are global (shaders/probe_field.glsl: cascade * probesPerVolume + storage).

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


#ifdef PROBE_RAY
// The blend of one update's rays into interior texels, in two steps so a pass may stage the rays
// in chunks (probe_blend.comp keeps them in shared memory): the sums over rays
// PROBE_RAY(rayBase + r), r < n, in directions PROBE_RAY_DIR(rayBase + r) (written by the trace
// pass, so the blend does no trigonometry), accumulated onto `sums` in ray order, then the new
// stored value from the sums of all the probe's rays.

// Irradiance texel `texel` (0..5 per axis): (rgb·w, w) of the cosine-weighted mean.
vec4 probeIrradianceTexelSums(uint rayBase, uint n, uvec2 texel, bool backfacesBlack, vec4 sums) {
  vec3 texelDir = probeTexelDirection(texel, kProbeIrradianceInterior);
  // No branch per ray: the texels of a subgroup face every way, so about half of them weigh any
  // given ray and a skipped ray saved nothing; a weight of 0 adds exactly nothing to the sums.
  for (uint r = 0u; r < n; ++r) {
    vec4 result = PROBE_RAY(rayBase + r);
    // Backface hits (negated depth) carry no light: left out, not blended as black (RTXGI).
    bool blended = result.w >= 0.0f || backfacesBlack;
    float w = blended ? probeIrradianceWeight(texelDir, vec3(PROBE_RAY_DIR(rayBase + r))) : 0.0f;
    sums += vec4(vec3(result) * w, w);
  }
  return sums;
}

// New stored irradiance from the sums: the mean (probeIrradianceFromSums), encoded with gamma,
// blended with the old stored value in encoded space with hysteresis h (M21 Eq. 1, Sec. 4.2);
// h = 0 for a texel never written; the per-texel change heuristic lowers h when asked (M21
// Sec. 4.3). No weighted ray: unchanged.
vec4 probeFinishIrradianceTexel(vec4 sums, vec4 oldStored, float h, float gamma, bool adaptive) {
  if (sums.w <= 0.0f) return oldStored;
  vec3 fresh = probeEncodeIrradiance(probeIrradianceFromSums(sums), gamma);
  vec3 old = vec3(oldStored);
  float hh = oldStored.w == 0.0f ? 0.0f : h;
  if (adaptive && hh > 0.0f) hh = probeAdjustHysteresis(old, fresh, hh);
  return vec4(probeHysteresisBlend3(old, fresh, hh), 1.0f);
}

// Depth texel `texel` (0..13 per axis): (w d, w d², w) of the power-cosine weighted moments.
vec3 probeDepthTexelSums(uint rayBase, uint n, uvec2 texel, float sharpness, vec3 sums) {
  vec3 texelDir = probeTexelDirection(texel, kProbeDepthInterior);
  for (uint r = 0u; r < n; ++r) {
    vec3 rayDir = vec3(PROBE_RAY_DIR(rayBase + r));
    if (dot(texelDir, rayDir) <= 0.0f) continue;  // weight 0: skip the pow
    float d = abs(PROBE_RAY(rayBase + r).w);  // backface depths are stored negated
    float w = probeDepthWeight(texelDir, rayDir, sharpness);
    sums += vec3(w * d, w * d * d, w);
  }
  return sums;
}

#ifdef PROBE_RAY_PATTERN
// Depth texels' ray lists: the same sums as probeDepthTexelSums over the rays its list (block
// `list` of PROBE_RAY_PATTERN, probe_layout.h kProbeDepthList*) names, `listed` of them, with the
// weights it holds, for the probe's rays [first, first + count) (PROBE_RAY indices; its rays start
// at rayBase). The rays left out weigh < kProbeDepthListFloor of the texel's nearest ray each,
// and every probe of the frame shares the pattern, so a texel reads ~13 rays and no pow instead
// of 128 and 128.
vec3 probeDepthTexelSumsListed(uint rayBase, uint first, uint count, uint list, uint listed,
                               vec3 sums) {
  for (uint e = 0u; e < listed; ++e) {
    vec4 pair = PROBE_RAY_PATTERN(list + 1u + e / 2u);
    bool even = (e & 1u) == 0u;
    uint ray = rayBase + floatBitsToUint(even ? pair.x : pair.z);
    if (ray < first || ray >= first + count) continue;
    float w = even ? pair.y : pair.w;
    float d = abs(PROBE_RAY(ray).w);  // backface depths are stored negated
    sums += vec3(w * d, w * d * d, w);
  }
  return sums;
}
#endif

// New stored (mean, mean²), blended with hysteresis h; a texel never written (0, 0) takes the
// fresh moments (every written texel has a positive mean: depths are > 0).
vec2 probeFinishDepthTexel(vec3 sums, vec2 oldStored, float h) {
  if (sums.z <= 0.0f) return oldStored;
  vec2 mean = vec2(sums.x / sums.z, sums.y / sums.z);
  bool fresh = oldStored.x == 0.0f && oldStored.y == 0.0f;
  return probeHysteresisBlend2(oldStored, mean, fresh ? 0.0f : h);
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

#endif  // PROBE_DEPTH
