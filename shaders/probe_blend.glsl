// Probe field, blend pass (probe_blend.comp; shaders/probe_field.glsl lists the pass files): the
// listed probes' rays into their interior texels (shaders/probe_update.glsl), each written with
// its border copies. Reads and writes PROBE_LIST(l), PROBE_VOLUME(c), PROBE_DATA(g),
// PROBE_HISTORY(g), PROBE_RAY(i), PROBE_IRRADIANCE(i), PROBE_DEPTH(i) (as listed by the classify
// and trace files).

// One interior texel of a listed probe's blend: which atlas texel, its hysteresis and the
// per-probe options (probeBlendTexelOf). The sums are accumulated in ray order by
// probeBlendAccumulate, over all rays at once (the CPU) or chunk by chunk (probe_blend.comp),
// then probeBlendFinish writes the texel.
struct ProbeBlendTexel {
  bool irradiance;  // else depth
  uvec2 texel;      // interior coordinates
  uint index;       // PROBE_IRRADIANCE / PROBE_DEPTH index
  float h;          // hysteresis
  float shape;      // irradiance: the encoding's gamma; depth: the weight's sharpness
  uint rayBase;     // this probe's first ray: list position x rays per probe
  uint n;           // rays per probe
  uint depthList;   // depth: PROBE_RAY_PATTERN index of the texel's ray list
  uint probe;       // global probe index
};

// Texel `local` (< 36 irradiance, else depth) of the probe at list position l.
ProbeBlendTexel probeBlendTexelOf(ProbeFrame f, uint l, uint local) {
  uint g = PROBE_LIST(l);
  ProbeVolume v = PROBE_VOLUME(g / f.counts.y);
  uint state = probeStateOf(PROBE_DATA(g));
  bool vigilant = state == kProbeVigilant;
  uvec4 hist = PROBE_HISTORY(g);
  uint left = probeHistoryVigilant(hist);  // after this update (classify counted it)
  bool closing = probeHistoryClosingMean(hist);
  bool drifting =
      (f.options.x & kProbeOptionLightsDrifting) != 0u && state == kProbeSleeping;
  const uint irrCount = kProbeIrradianceInterior * kProbeIrradianceInterior;
  ProbeBlendTexel t;
  t.probe = g;
  t.irradiance = local < irrCount;
  t.n = v.countsRays.w;
  t.rayBase = l * t.n;
  if (t.irradiance) {
    t.texel = uvec2(local % kProbeIrradianceInterior, local / kProbeIrradianceInterior);
    t.index = probeIrradianceIndex(g, t.texel + uvec2(kProbeBorderTexels));
    t.h = vigilant ? probeVigilantHysteresis(f, v.blend.x, left, closing)
                   : drifting ? probeDriftHysteresis(f, v.blend.x) : v.blend.x;
    t.shape = v.blend.w;
    t.depthList = 0u;
  } else {
    uint d = local - irrCount;
    t.texel = uvec2(d % kProbeDepthInterior, d / kProbeDepthInterior);
    t.index = probeDepthIndex(g, t.texel + uvec2(kProbeBorderTexels));
    t.h = vigilant ? min(v.blend.y, f.view.w) : v.blend.y;
    t.shape = v.visibility.y;
    // After the rotations, the lists of the probe's slot (each slot's set of interior texels).
    uint lists = probeHistorySlot(hist) * kProbeDepthInterior * kProbeDepthInterior + d;
    t.depthList = 3u * f.selection.z + lists * kProbeDepthListVec4s;
  }
  return t;
}

// Adds rays [first, first + count) (PROBE_RAY indices) of the texel's probe to its sums:
// irradiance (rgb·w, w), depth (w d, w d², w, 0).
vec4 probeBlendAccumulate(ProbeFrame f, ProbeBlendTexel t, uint first, uint count, vec4 sums) {
  if (t.irradiance)
    return probeIrradianceTexelSums(first, count, t.texel,
                                    (f.options.x & kProbeOptionBackfacesBlack) != 0u, sums);
  uint listed = floatBitsToUint(PROBE_RAY_PATTERN(t.depthList).x);
  if (listed != kProbeDepthListDense)
    return vec4(probeDepthTexelSumsListed(t.rayBase, first, count, t.depthList, listed, vec3(sums)),
                0.0f);
  return vec4(probeDepthTexelSums(first, count, t.texel, t.shape, vec3(sums)), 0.0f);
}

// Writes the texel's new stored value from the sums of all its probe's rays, and the same value
// to the border texels that copy it (M21 Sec. 3: the tile's one-texel border lets a bilinear
// lookup filter across the octahedral seams; a pass of its own once copied them, 0.035 ms a
// frame in Sponza on the H100).
void probeBlendFinish(ProbeFrame f, ProbeBlendTexel t, vec4 sums) {
  uvec2 tileTexel = t.texel + uvec2(kProbeBorderTexels);
  if (t.irradiance) {
    vec4 v = probeFinishIrradianceTexel(sums, PROBE_IRRADIANCE(t.index), t.h, t.shape,
                                        (f.options.x & kProbeOptionAdaptiveHysteresis) != 0u);
    PROBE_IRRADIANCE(t.index) = v;
    for (uint k = 0u; k < 8u; ++k) {
      uvec2 c = probeBorderCopyCandidate(tileTexel, kProbeIrradianceTexels, k);
      if (probeBorderSource(c, kProbeIrradianceTexels) == tileTexel)
        PROBE_IRRADIANCE(probeIrradianceIndex(t.probe, c)) = v;
    }
  } else {
    vec2 v = probeFinishDepthTexel(vec3(sums), PROBE_DEPTH(t.index), t.h);
    PROBE_DEPTH(t.index) = v;
    for (uint k = 0u; k < 8u; ++k) {
      uvec2 c = probeBorderCopyCandidate(tileTexel, kProbeDepthTexels, k);
      if (probeBorderSource(c, kProbeDepthTexels) == tileTexel)
        PROBE_DEPTH(probeDepthIndex(t.probe, c)) = v;
    }
  }
}

// M21 Sec. 5: a probe with more than a quarter of its rays on backfaces is inside geometry
// (with states on; once per probe, before or after its texels, which do not read it), from the
// count of its rays that hit a backface.
void probeBlendStatesFromCount(ProbeFrame f, uint l, uint backfaces) {
  uint g = PROBE_LIST(l);
  uint n = PROBE_VOLUME(g / f.counts.y).countsRays.w;
  uvec4 hist = PROBE_HISTORY(g);
  bool inside = 4u * backfaces > n;
  PROBE_HISTORY(g) = uvec4(hist.x, hist.y, hist.z, (hist.w & 0x7fffffffu) | (inside ? 0x80000000u : 0u));
}

// The same, counting the rays from PROBE_RAY_STORED one after the other.
void probeBlendStates(ProbeFrame f, uint l) {
  if ((f.options.x & kProbeOptionStates) == 0u) return;
  uint n = PROBE_VOLUME(PROBE_LIST(l) / f.counts.y).countsRays.w;
  uint backfaces = 0u;
  for (uint r = 0u; r < n; ++r) backfaces += PROBE_RAY_STORED(l * n + r).w < 0.0f ? 1u : 0u;
  probeBlendStatesFromCount(f, l, backfaces);
}

// Blend pass body (interior texels) with every ray at once: `local` < 36 irradiance texel, else
// depth texel (the CPU reference; probe_blend.comp stages the same sums through shared memory).
void probeBlendPass(ProbeFrame f, uint l, uint local) {
  if (local == 0u) probeBlendStates(f, l);
  ProbeBlendTexel t = probeBlendTexelOf(f, l, local);
  probeBlendFinish(f, t, probeBlendAccumulate(f, t, t.rayBase, t.n, vec4(0.0f)));
}
