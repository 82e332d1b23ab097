// Probe field, blend pass (probe_blend.comp; shaders/probe_field.glsl lists the pass files): the
// listed probes' rays into their interior texels (shaders/probe_update.glsl), then the border
// copies. Reads and writes PROBE_LIST(l), PROBE_VOLUME(c), PROBE_DATA(g), PROBE_HISTORY(g),
// PROBE_RAY(i), PROBE_IRRADIANCE(i), PROBE_DEPTH(i) (as listed by the classify and trace files).

// Blend pass body (interior texels): `local` < 36 irradiance texel, else depth texel.
void probeBlendPass(ProbeFrame f, uint l, uint local) {
  uint g = PROBE_LIST(l);
  ProbeVolume v = PROBE_VOLUME(g / f.counts.y);
  uint n = v.countsRays.w;
  bool vigilant = probeStateOf(PROBE_DATA(g)) == kProbeVigilant;
  bool adaptive = (f.options.x & kProbeOptionAdaptiveHysteresis) != 0u;
  const uint irrCount = kProbeIrradianceInterior * kProbeIrradianceInterior;
  if (local == 0u && (f.options.x & kProbeOptionStates) != 0u) {
    // M21 Sec. 5: a probe with more than a quarter of its rays on backfaces is inside geometry.
    uint backfaces = 0u;
    for (uint r = 0u; r < n; ++r) backfaces += PROBE_RAY(l * n + r).w < 0.0f ? 1u : 0u;
    uvec4 hist = PROBE_HISTORY(g);
    bool inside = 4u * backfaces > n;
    PROBE_HISTORY(g) = uvec4(hist.x, hist.y, hist.z, (hist.w & 0x7fffffffu) | (inside ? 0x80000000u : 0u));
  }
  if (local < irrCount) {
    uvec2 texel = uvec2(local % kProbeIrradianceInterior, local / kProbeIrradianceInterior);
    uint i = probeIrradianceIndex(g, texel + uvec2(kProbeBorderTexels));
    float h = vigilant ? min(v.blend.x, f.view.w) : v.blend.x;
    PROBE_IRRADIANCE(i) =
        probeBlendIrradianceTexel(l * n, n, texel, PROBE_IRRADIANCE(i), h, v.blend.w, adaptive,
                                  (f.options.x & kProbeOptionBackfacesBlack) != 0u);
  } else {
    uint d = local - irrCount;
    uvec2 texel = uvec2(d % kProbeDepthInterior, d / kProbeDepthInterior);
    uint i = probeDepthIndex(g, texel + uvec2(kProbeBorderTexels));
    float h = vigilant ? min(v.blend.y, f.view.w) : v.blend.y;
    PROBE_DEPTH(i) = probeBlendDepthTexel(l * n, n, texel, PROBE_DEPTH(i), h, v.visibility.y);
  }
}

// Border pass body: tile texel `local` (< 64 irradiance, else depth) copies its source.
void probeBorderPass(uint l, uint local) {
  uint g = PROBE_LIST(l);
  const uint irrTile = kProbeIrradianceTexels * kProbeIrradianceTexels;
  if (local < irrTile) {
    uvec2 t = uvec2(local % kProbeIrradianceTexels, local / kProbeIrradianceTexels);
    uvec2 src = probeBorderSource(t, kProbeIrradianceTexels);
    if (src != t) PROBE_IRRADIANCE(probeIrradianceIndex(g, t)) = PROBE_IRRADIANCE(probeIrradianceIndex(g, src));
  } else {
    uint d = local - irrTile;
    uvec2 t = uvec2(d % kProbeDepthTexels, d / kProbeDepthTexels);
    uvec2 src = probeBorderSource(t, kProbeDepthTexels);
    if (src != t) PROBE_DEPTH(probeDepthIndex(g, t)) = PROBE_DEPTH(probeDepthIndex(g, src));
  }
}
