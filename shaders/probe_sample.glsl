// The probe field's irradiance(x, n, view) (shaders/probe_field.glsl lists the pass files): the
// queries of probe_sample.comp, the multi-bounce term of probe_trace.glsl and engines' own
// shaders (shaders/include/sdfstream/probe_sample.glsl, installed). Reads only
//   PROBE_VOLUME(c)  -> ProbeVolume of cascade c
//   PROBE_DATA(g)    -> vec4 of global probe g (offset, state)
//   PROBE_IRRADIANCE(i), PROBE_DEPTH(i) through shaders/probe_update.glsl
//   SDF_CASCADE(c), SDF_PAGE(i), SDF_DIST_WORD(i) through sdfTraceStackFrom (SDF visibility)
// after shaders/probe_field.glsl, shaders/sdf_trace.glsl (SDF_CASCADE defined) and
// shaders/probe_update.glsl (PROBE_DEPTH defined).

// ---- Sampling: irradiance(x, n, view) (issue 5 item 7) ---------------------------------------

// SDFDDGI's visibility (Sec. 4.2): the SDF is traced from the probe towards the receiver; a
// surface in between makes the probe invisible (a tiny weight, crushed to nothing below). On
// top of Chebyshev by default: coarse cascades' depth texels mix misses and near hits (large
// variance), where Chebyshev alone lets light through one-voxel walls.
float probeSdfVisibility(ProbeFrame f, uint c, vec3 probe, vec3 receiver) {
  vec3 d = receiver - probe;
  float r = length(d);
  if (r < 1e-4f) return 1.0f;
  SdfStackResult s = sdfTraceStackFrom(probe, d / r, 0.0f, r, 64u, f.trace.x, c, f.counts.x);
  return s.r.hit ? 1e-4f : 1.0f;
}

// The SDF test's answer where the depth moments already give it (GI "Visibility" in
// docs/DECISIONS.md), else -1 (trace). The test exists for the corners Chebyshev would let
// through a thin wall: depth texels that mix near hits and far ones (large variance). Where the
// bilinearly filtered moments are decisive the trace is skipped and its likely answer used: a
// probe hidden beyond doubt (Chebyshev weight below 1e-3) is blocked (1e-4, as a hit), and a
// receiver nearer than the mean depth of a narrow distribution (sigma <= 10% of the mean: every
// ray near that direction went at least about as far, so no wall stands in between) is visible.
// Without Chebyshev, or with kProbeOptionSdfEverywhere, every corner is traced.
float probeSdfVisibilityPresumed(ProbeFrame f, vec2 moments, float r, float chebyshev) {
  if ((f.options.x & (kProbeOptionSdfEverywhere | kProbeOptionNoChebyshev)) != 0u) return -1.0f;
  if (chebyshev < 1e-3f) return 1e-4f;
  float variance = max(moments.y - moments.x * moments.x, 0.0f);
  return r <= moments.x && variance <= 0.01f * moments.x * moments.x ? 1.0f : -1.0f;
}

// One volume's estimate: rgb and the summed weight (0 when no probe of the cage is usable).
// M21 Sec. 2.2 and 4.1 / H22 Sec. 4.4: the 8 probes of the cage around the biased receiver,
// each weighted by backface (wrap) x visibility (Chebyshev on the depth moments towards the
// biased receiver, and/or the SDF test) crushed below 0.2, x trilinear. Probes that are off or were
// never updated get weight 0; relocated probes are used at their relocated positions.
vec4 probeVolumeIrradiance(ProbeFrame f, uint c, vec3 x, vec3 n, vec3 view, bool sdfVisibility) {
  ProbeVolume v = PROBE_VOLUME(c);
  float spacing = v.originSpacing.w;
  vec3 origin = vec3(v.originSpacing);
  vec3 biased = x + probeSelfShadowBias(n, view, spacing, v.visibility.x);
  vec3 g = (biased - origin) / spacing;
  ivec3 maxBase = ivec3(max(int(v.countsRays.x) - 2, 0), max(int(v.countsRays.y) - 2, 0),
                        max(int(v.countsRays.z) - 2, 0));
  ivec3 base = clamp(ivec3(floor(g)), ivec3(0), maxBase);
  vec3 alpha = clamp(g - vec3(base), vec3(0.0f), vec3(1.0f));
  uint volumeBase = c * f.counts.y;
  vec3 sum = vec3(0.0f);
  float sumW = 0.0f;
  for (uint corner = 0u; corner < 8u; ++corner) {
    ivec3 lc = base + ivec3(int(corner & 1u), int((corner >> 1u) & 1u), int((corner >> 2u) & 1u));
    lc = min(lc, ivec3(int(v.countsRays.x) - 1, int(v.countsRays.y) - 1, int(v.countsRays.z) - 1));
    uint probe = volumeBase + probeStorageIndex(v, lc);
    vec4 data = PROBE_DATA(probe);
    if (probeStateOf(data) == kProbeOff) continue;
    if (PROBE_IRRADIANCE(probeIrradianceIndex(probe, uvec2(1u, 1u))).w == 0.0f) continue;
    vec3 p = probeGridPosition(v, lc) + vec3(data);
    vec3 toProbe = p - x;
    float lenToProbe = length(toProbe);
    vec3 dirToProbe = lenToProbe > 1e-6f ? toProbe / lenToProbe : n;
    float w = probeBackfaceWeight(dirToProbe, n);
    vec3 fromProbe = biased - p;
    float r = length(fromProbe);
    vec3 dirFromProbe = r > 1e-6f ? fromProbe / r : n;
    vec2 moments = vec2(0.0f);
    float chebyshev = 1.0f;
    if ((f.options.x & kProbeOptionNoChebyshev) == 0u) {
      moments = probeSampleDepth(probe, dirFromProbe);
      chebyshev = probeChebyshevWeight(moments, r, v.visibility.w);
    }
    w *= chebyshev;
    if (sdfVisibility) {
      float presumed = probeSdfVisibilityPresumed(f, moments, r, chebyshev);
      w *= presumed >= 0.0f ? presumed : probeSdfVisibility(f, c, p, biased);
    }
    w = probeCrushWeight(max(w, 1e-6f), 0.2f);
    w *= probeTrilinearWeight(alpha, corner);
    sum += probeSampleIrradiance(probe, n, v.blend.w) * w;
    sumW += w;
  }
  return sumW > 0.0f ? vec4(sum / sumW, sumW) : vec4(0.0f);
}

// The field's irradiance at x (cascade-0 voxels) for unit normal n seen from view: the finest
// cascade whose probe grid holds x at least half a spacing inside, blended over the next spacing
// into the next coarser cascade (a smooth band, no seams where cascades meet; GS "cascades").
// onlyCascade >= 0 samples that cascade alone (tests and debugging).
vec3 probeFieldIrradiance(ProbeFrame f, vec3 x, vec3 n, vec3 view, bool allowSdfVisibility,
                          int onlyCascade) {
  bool sdfVisibility = allowSdfVisibility && (f.options.x & kProbeOptionSdfVisibility) != 0u;
  if (onlyCascade >= 0) return vec3(probeVolumeIrradiance(f, uint(onlyCascade), x, n, view, sdfVisibility));
  vec3 result = vec3(0.0f);
  float remaining = 1.0f;
  for (uint c = 0u; c < f.counts.x; ++c) {
    ProbeVolume v = PROBE_VOLUME(c);
    vec3 g = (x - vec3(v.originSpacing)) / v.originSpacing.w;
    vec3 hi = vec3(float(v.countsRays.x) - 1.0f, float(v.countsRays.y) - 1.0f,
                   float(v.countsRays.z) - 1.0f) - g;
    float edge = min(min(min(g.x, g.y), g.z), min(min(hi.x, hi.y), hi.z));
    bool last = c + 1u == f.counts.x;
    if (edge <= 0.5f && !last) continue;
    float w = last ? 1.0f : clamp(edge - 0.5f, 0.0f, 1.0f);
    vec4 e = probeVolumeIrradiance(f, c, x, n, view, sdfVisibility);
    if (e.w <= 0.0f) continue;
    result += vec3(e) * (remaining * w);
    remaining *= 1.0f - w;
    if (remaining <= 0.0f) break;
  }
  float used = 1.0f - remaining;
  return used > 0.0f ? result / used : vec3(0.0f);
}
