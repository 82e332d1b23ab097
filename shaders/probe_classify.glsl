// Probe field, classify pass (probe_classify.comp; shaders/probe_field.glsl lists the pass
// files): scroll reset of newly entered probes, SDFDDGI relocation, history (convergence), state,
// hit-cache invalidation, one invocation per probe of every volume. Reads and writes
//   PROBE_VOLUME(c), PROBE_DATA(g), PROBE_IRRADIANCE(i), PROBE_DEPTH(i) (reset)
//   PROBE_HISTORY(g)         -> uvec4 history of global probe g (probeHistoryPack)
//   PROBE_CACHE(i)           -> uvec2 hit-cache entry i
//   PROBE_ROTATION(r, k)     -> vec4 column k of hit-cache rotation slot r
//   PROBE_PAGE_CHANGED(c, i) -> bool: page-table entry i of cascade c changed this frame
//   PROBE_STAT_ADD(i, v)     -> atomic add to frame statistic i, returns the previous value
//   SDF_CASCADE(c) and the SDF sampling of shaders/sdf_trace.glsl
// and, with OBJ_FRAME, the moving objects of shaders/object_trace.glsl.

// ---- Classification: relocation (SDFDDGI Sec. 4.1) and states (M21 Sec. 5) -------------------

struct ProbeSdf {
  float distance;  // cascade-0 voxels; for a page without a brick its conservative bound
  bool resident;
  vec3 gradient;   // unit (resident only)
};

// The SDF at p0 in the finest cascade from `cascade` on whose window holds it (probes on a
// window's far faces, at 128, read the last sample layer inside: the field is continuous).
ProbeSdf probeSdfAt(uint cascade, uint cascadeCount, vec3 p0) {
  ProbeSdf r;
  r.gradient = vec3(0.0f, 1.0f, 0.0f);
  r.distance = 0.0f;  // outside every window: nothing known
  r.resident = false;
  for (uint c = cascade; c < cascadeCount; ++c) {
    CascadeTraceParams cp = SDF_CASCADE(c);
    float scale = cp.offsetScale.w;
    vec3 p = (p0 - vec3(cp.offsetScale.x, cp.offsetScale.y, cp.offsetScale.z)) / scale;
    if (p.x < 0.0f || p.y < 0.0f || p.z < 0.0f || p.x > 128.0f || p.y > 128.0f || p.z > 128.0f)
      continue;
    p = min(p, vec3(127.999f));
    SdfSample s = sdfSampleCascade(p, cp.toroidal);
    r.resident = s.resident;
    r.distance = s.distance * scale;
    if (s.resident) r.gradient = sdfNearNormal(p, cp.toroidal);
    return r;
  }
  return r;
}

// SDFDDGI relocation: a probe closer to a surface than minDistance (inside geometry included) is
// pushed along the SDF gradient by the missing distance, a few fixed-point steps, the offset
// clamped to 0.45 of the spacing per axis so that the probe stays inside its cell.
vec3 probeRelocate(uint cascade, uint cascadeCount, vec3 gridPos, float spacing,
                   float minDistance) {
  vec3 offset = vec3(0.0f);
  float limit = 0.45f * spacing;
  for (int i = 0; i < 4; ++i) {
    ProbeSdf d = probeSdfAt(cascade, cascadeCount, gridPos + offset);
    if (!d.resident || d.distance >= minDistance) break;
    vec3 next = clamp(offset + d.gradient * (minDistance - d.distance), vec3(-limit), vec3(limit));
    // Never move a probe out of every window (nothing would be known about it there).
    ProbeSdf there = probeSdfAt(cascade, cascadeCount, gridPos + next);
    if (!there.resident && there.distance == 0.0f) break;
    offset = next;
  }
  return offset;
}

#ifdef OBJ_FRAME
// Whether a probe may stand where the static SDF reads s: not inside static geometry, and not
// outside every window (nothing would be known about it there).
bool probeSdfOpen(ProbeSdf s) { return s.distance >= 0.0f && (s.resident || s.distance > 0.0f); }

// Relocation away from moving objects, as probeRelocate does from the static SDF: a probe closer
// than minDistance to the nearest listed object (inside it included) steps along that object's
// distance gradient, within the same 0.45-spacing limit, never into static geometry. A probe on
// an object's face would otherwise be off, and the receivers beside the face would read only the
// probes a whole spacing away (the bounce right at the face is the strongest). Probes deeper
// inside than the limit allows stay inside and are turned off. Objects whose bounding radius is
// below minRadius are left out: they shade little of a probe's sphere, and relocating around
// every small mover costs a hit-cache flush per move (the H200 stress scene of 0.3-2 m objects:
// 16x the fresh rays at 10,000 objects).
vec3 probeRelocateFromObjects(uint cascade, uint cascadeCount, vec3 gridPos, vec3 offset,
                              float spacing, float minDistance, float minRadius) {
  float limit = 0.45f * spacing;
  for (int i = 0; i < 4; ++i) {
    vec3 p = gridPos + offset;
    vec2 near = objNearestListed(p, cascade, minRadius);
    if (near.x >= minDistance) break;
    uint inst = uint(near.y);
    float h = 0.125f * minDistance;
    vec3 grad = vec3(objInstanceDistance(inst, p + vec3(h, 0, 0)) -
                         objInstanceDistance(inst, p - vec3(h, 0, 0)),
                     objInstanceDistance(inst, p + vec3(0, h, 0)) -
                         objInstanceDistance(inst, p - vec3(0, h, 0)),
                     objInstanceDistance(inst, p + vec3(0, 0, h)) -
                         objInstanceDistance(inst, p - vec3(0, 0, h)));
    if (dot(grad, grad) < 1e-12f) break;  // deep inside a flat distance: nowhere to go
    grad = normalize(grad);
    vec3 next = clamp(offset + grad * (minDistance - near.x), vec3(-limit), vec3(limit));
    if (next == offset) break;
    if (!probeSdfOpen(probeSdfAt(cascade, cascadeCount, gridPos + next))) break;
    offset = next;
  }
  return offset;
}
#endif

// Whether probe storage s of v holds a position that was outside the volume last frame (the
// newly entered planes of a scroll, GS "scrolling"), or the whole volume was reset.
bool probeEntered(ProbeVolume v, uint s) {
  if (v.moved.w != 0) return true;
  ivec3 before = probeLogicalCoord(v, s) + ivec3(v.moved.x, v.moved.y, v.moved.z);
  return before.x < 0 || before.y < 0 || before.z < 0 || before.x >= int(v.countsRays.x) ||
         before.y >= int(v.countsRays.y) || before.z >= int(v.countsRays.z);
}

// The state of a probe (M21 Sec. 5): off when its relocated position is still inside geometry
// or when no surface lies within two spacings (a page bound beyond the cage diagonal plus the
// self-shadow bias: no surface receiver can use it; queries in empty space then fall through to
// coarser cascades); vigilant while the vigilant countdown runs; sleeping after 4 updates' worth
// of quiet rotation cycles (one cycle of the hit cache's 4 rotations; 4 updates without it).
uint probeState(ProbeFrame f, ProbeSdf sdf, float spacing, uvec4 history) {
  if ((f.options.x & kProbeOptionStates) == 0u)
    return probeHistoryVigilant(history) > 0u ? kProbeVigilant : kProbeAwake;
  if (sdf.resident && sdf.distance < 0.0f) return kProbeOff;
  if (probeHistoryInside(history)) return kProbeOff;  // M21 Sec. 5: mostly backface hits
  if (!sdf.resident && sdf.distance >= 2.0f * spacing) return kProbeOff;
  if (probeHistoryVigilant(history) > 0u) return kProbeVigilant;
  return probeHistoryQuiet(history) * max(f.selection.z, 1u) >= 4u ? kProbeSleeping : kProbeAwake;
}

// Exit distance of a ray from the box [lo, lo + size]³ (it starts inside or the result is <= 0).
float probeBoxExit(vec3 o, vec3 invDir, vec3 lo, float size) {
  return sdfBoxClip(o, invDir, lo, lo + vec3(size)).y;
}

// Whether a cached result for the ray (o, dir) from a probe of cascade c is still what a fresh
// trace would give after this frame's scrolls (GS "Caching rays"): a hit stays valid while the
// ray's path through every cascade before the hit cascade is unchanged (same exit distance from
// each window, so the same side and point: the slides' "side the ray exits from remains the
// same") and the hit point is still inside its cascade's window on a page that did not change;
// a miss while its exits from all cascades are unchanged.
bool probeCacheStillValid(ProbeFrame f, uint c, vec3 o, vec3 dir, uvec2 e) {
  bool hit = (e.y & kHitCacheHit) != 0u;
  uint h = hit ? probeCacheCascade(e) : f.counts.x;
  vec3 invDir = sdfSafeInverse(dir);
  float tEntry = 0.0f;  // where the ray enters cascade k (the same before and after, so far)
  uint last = min(h, f.counts.x - 1u);
  for (uint k = c; k <= last; ++k) {
    CascadeTraceParams cp = SDF_CASCADE(k);
    ProbeVolume vk = PROBE_VOLUME(k);
    float scale = cp.offsetScale.w;
    vec3 lo = vec3(cp.offsetScale.x, cp.offsetScale.y, cp.offsetScale.z);
    vec3 prevLo = vec3(vk.prevWindow);
    vec3 p = o + dir * tEntry;
    // sdfTraceStackFrom's own test, in each window's units: is cascade k traced at all?
    bool inNow = sdfInsideWindow((p - lo) / scale);
    bool inBefore = sdfInsideWindow((p - prevLo) / scale);
    if (inNow != inBefore) return false;
    // A ray starting on a face of a moved window is ambiguous under rounding (it may be traced
    // in this cascade or the next): re-trace it.
    vec3 q = (p - lo) / scale;
    float face = min(min(min(abs(q.x), abs(q.y)), abs(q.z)),
                     min(min(abs(128.0f - q.x), abs(128.0f - q.y)), abs(128.0f - q.z)));
    if (lo != prevLo && face < 1e-2f) return false;
    if (!inNow || k == h) continue;  // the hit cascade: its entry is what matters
    if (lo == prevLo) {
      tEntry = max(tEntry, probeBoxExit(o, invDir, lo, 128.0f * scale));
      continue;
    }
    float now = probeBoxExit(o, invDir, lo, 128.0f * scale);
    float before = probeBoxExit(o, invDir, prevLo, 128.0f * scale);
    if (abs(now - before) > 1e-3f * scale) return false;
    tEntry = max(tEntry, now);
  }
  if (!hit) return true;
  CascadeTraceParams ch = SDF_CASCADE(h);
  float scale = ch.offsetScale.w;
  vec3 p = (o + dir * uintBitsToFloat(e.x) - vec3(ch.offsetScale.x, ch.offsetScale.y, ch.offsetScale.z)) / scale;
  if (p.x < 0.0f || p.y < 0.0f || p.z < 0.0f || p.x >= 128.0f || p.y >= 128.0f || p.z >= 128.0f)
    return false;
  uint page = sdfPageIndex(sdfPageOf(p), ch.toroidal) - ch.toroidal.w;
  return !PROBE_PAGE_CHANGED(h, page);
}

// ---- Pass bodies (one call per GPU invocation; the CPU reference loops over the same) --------

vec3 probeMeanIrradiance(uint probe, float gamma) {
  vec3 sum = vec3(0.0f);
  for (uint y = 1u; y <= kProbeIrradianceInterior; ++y)
    for (uint x = 1u; x <= kProbeIrradianceInterior; ++x)
      sum += probeDecodeIrradiance(vec3(PROBE_IRRADIANCE(probeIrradianceIndex(probe, uvec2(x, y)))), gamma);
  return sum * (1.0f / float(kProbeIrradianceInterior * kProbeIrradianceInterior));
}

// Ray `ray` of n in hit-cache rotation slot `slot` (the ray pattern's first 3 x slots vec4; with
// the cache off, slot 0 holds this frame's fresh rotation).
vec3 probeRotationSlotDirection(uint slot, uint ray, uint n) {
  mat3 r = mat3(vec3(PROBE_ROTATION(slot, 0u)), vec3(PROBE_ROTATION(slot, 1u)),
                vec3(PROBE_ROTATION(slot, 2u)));
  return probeRayDirection(ray, n, r);
}

// Classify pass, one invocation per probe of every volume: scroll reset of newly entered probes,
// relocation, history (convergence), state, hit-cache invalidation.
void probeClassifyPass(ProbeFrame f, uint g) {
  uint c = g / f.counts.y;
  uint s = g % f.counts.y;
  ProbeVolume v = PROBE_VOLUME(c);
  float spacing = v.originSpacing.w;
  vec3 grid = probeGridPosition(v, probeLogicalCoord(v, s));
  vec4 oldData = PROBE_DATA(g);
  uvec4 hist = PROBE_HISTORY(g);
  bool entered = (f.options.x & kProbeOptionFirstFrame) != 0u || probeEntered(v, s);
  uint quiet = probeHistoryQuiet(hist);
  uint vigilant = probeHistoryVigilant(hist);
  uint age = probeHistoryAge(hist);
  bool closingMean = probeHistoryClosingMean(hist);
  bool inside = probeHistoryInside(hist);
  vec3 mean = vec3(uintBitsToFloat(hist.x), uintBitsToFloat(hist.y), uintBitsToFloat(hist.z));
  if (entered) {
    for (uint t = 0u; t < kProbeIrradianceTexels * kProbeIrradianceTexels; ++t)
      PROBE_IRRADIANCE(g * kProbeIrradianceTexels * kProbeIrradianceTexels + t) = vec4(0.0f);
    for (uint t = 0u; t < kProbeDepthTexels * kProbeDepthTexels; ++t)
      PROBE_DEPTH(g * kProbeDepthTexels * kProbeDepthTexels + t) = vec2(0.0f);
    quiet = 0u;
    vigilant = f.selection.w & 255u;
    closingMean = false;
    age = 0u;
    inside = false;
    mean = vec3(0.0f);
  } else {
    // The last update's hysteresis (the blend's rule, with last frame's state and options).
    bool driftLast = (f.options.x & kProbeOptionDriftedBefore) != 0u &&
                     probeStateOf(oldData) == kProbeSleeping;
    float hLast = vigilant > 0u ? probeVigilantHysteresis(f, v.blend.x, vigilant, closingMean)
                  : driftLast ? probeDriftHysteresis(f, v.blend.x) : v.blend.x;
    // Updated by the previous frame, through the last of the hit cache's rotation slots: measure
    // how much the stored mean moved over the cycle of rotations (the mean xyz holds the value
    // at the previous cycle's end). Each rotation's 128 fixed directions have their own bias
    // against the field, as large as a few per cent of the mean where a few rays see a sunlit
    // patch, so an update's estimate against the stored mean measured that bias, and such probes
    // never slept; over a whole cycle the biases cancel. Without the cache a cycle is one update.
    uint slots = max(f.selection.z, 1u);
    if (age == 0u && probeHistorySlot(hist) == slots - 1u) {
      vec3 now = probeMeanIrradiance(g, v.blend.w);
      vec3 delta = abs(now - mean);
      vec3 top = max(now, mean);
      float change = max(delta.x, max(delta.y, delta.z)) /
                     max(max(top.x, max(top.y, top.z)), 1e-4f);
      // The blend moved the stored mean by 1 - h^slots of the gap to the cycle's estimate: judge
      // the gap, not the step, or a high hysteresis would put unconverged probes to sleep.
      float kept = 1.0f;  // h^slots by multiplication, so the GPU and the CPU agree exactly
      for (uint k = 0u; k < slots; ++k) kept *= hLast;
      float gap = change / max(1.0f - kept, 1e-3f);
      // Vigilant updates (low hysteresis) are noisy: only calm updates count towards sleep, so
      // a probe never falls asleep holding the noise of its fast-converging phase.
      // A drifting refresh is calm too: its low hysteresis follows the light, not the noise.
      quiet = gap < f.trace.z && (hLast == v.blend.x || driftLast) ? quiet + 1u : 0u;
      mean = now;
    }
    if (age == 0u && vigilant > 0u) vigilant -= 1u;
    // After the count-down: a switch's vigilance is this update and the ones after it, all of
    // them (its closing mean, probeVigilantHysteresis, then spans whole rotation cycles).
    if ((f.options.x & kProbeOptionLightsChanged) != 0u) {
      vigilant = (f.selection.w >> 16u) & 255u;
      closingMean = true;
      quiet = 0u;
    }
    age += 1u;
  }
  vec3 offset = vec3(0.0f);
  if ((f.options.x & kProbeOptionRelocation) != 0u) {
    offset = probeRelocate(c, f.counts.x, grid, spacing, f.trace.y * spacing);
#ifdef OBJ_FRAME
    if (probeObjectsReach(f, c)) {
      // Sticky: the static offset (home) when it is clear of every object; else last frame's
      // offset while that is still clear; else relocate afresh. A passing object then moves a
      // probe once rather than every frame, and each move flushes the probe's hit cache
      // (measured on the H200 before this rule: 5x the fresh rays at 1,000 moving objects).
      float minDistance = f.trace.y * spacing;
      float minRadius = kProbeObjectMinRadius * spacing;
      vec3 previous = vec3(oldData);
      if (objNearestListed(grid + offset, c, minRadius).x < minDistance) {
        bool keep = !entered && previous != offset &&
                    probeSdfOpen(probeSdfAt(c, f.counts.x, grid + previous)) &&
                    objNearestListed(grid + previous, c, minRadius).x >= minDistance;
        offset = keep ? previous
                      : probeRelocateFromObjects(c, f.counts.x, grid, offset, spacing, minDistance,
                                                 minRadius);
      }
    }
#endif
  }
  ProbeSdf sdf = probeSdfAt(c, f.counts.x, grid + offset);
  // The inside verdict holds until the probe moves or the page under it changes (streaming).
  if (offset != vec3(oldData)) inside = false;
  else if (inside) {
    CascadeTraceParams cp = SDF_CASCADE(c);
    vec3 local = (grid + offset - vec3(cp.offsetScale.x, cp.offsetScale.y, cp.offsetScale.z)) / cp.offsetScale.w;
    uint page = sdfPageIndex(sdfPageOf(local), cp.toroidal) - cp.toroidal.w;
    if (PROBE_PAGE_CHANGED(c, page)) inside = false;
  }
#ifdef OBJ_FRAME
  // Moving objects: probes near one that moved this frame turn vigilant (low hysteresis for a
  // few frames, M21 Sec. 5); a probe inside an object is off (sampling skips it) rather than
  // blended towards the black of its backface hits, and keeps its irradiance for when the
  // object has passed.
  bool insideObject = false;
  if ((f.options.x & kProbeOptionObjects) != 0u && !entered && objMovedNear(grid + offset, c)) {
    vigilant = max(vigilant, (f.selection.w >> 8u) & 255u);
    quiet = 0u;
  }
  if (probeObjectsReach(f, c)) {
    float objDistance = objNearestListed(grid + offset, c, 0.0f).x;
    insideObject = objDistance < 0.0f;
    // A surface within reach makes a probe useful whether it is static or an object's: an
    // object flying far from static geometry keeps the probes around it (its cards' indirect
    // light and the receivers near it read them).
    if (!sdf.resident) sdf.distance = min(sdf.distance, max(objDistance, 0.0f));
  }
#endif
  uvec4 newHist =
      probeHistoryPack(mean, quiet, probeHistorySlot(hist), vigilant, age, closingMean, inside);
  uint state = probeState(f, sdf, spacing, newHist);
#ifdef OBJ_FRAME
  if (insideObject) state = kProbeOff;
#endif
  PROBE_STAT_ADD(kProbeStatStates + state, 1u);

  if ((f.options.x & kProbeOptionHitCache) != 0u) {
    uint n = v.countsRays.w;
    uint slots = f.selection.z;
    uint base = g * slots * n;
    bool moved = offset != vec3(oldData);
    // The other probes' entries are checked by the cache-check pass, an invocation each.
    if (entered || moved)
      for (uint i = 0u; i < slots * n; ++i) PROBE_CACHE(base + i) = uvec2(0u);
  }
  PROBE_DATA(g) = vec4(offset, float(state));
  PROBE_HISTORY(g) = newHist;
}

// Hit-cache check pass (probe_cache_check.comp), after classify, when a window scrolled or pages
// changed (kProbeOptionCacheCheck): entry i of the hit cache (probe i / (slots · n), then slot,
// then ray) is dropped when probeCacheStillValid says a fresh trace could now differ. One
// invocation per entry: as a loop over the probe's entries inside classify, one thread walked
// up to 512 entries serially and a scrolling frame's classify took 0.49 ms on the H200 instead
// of 0.06. Entries of probes that entered or moved were already cleared by classify, and the
// probe's offset is the one classify just wrote.
void probeCacheCheckPass(ProbeFrame f, uint i) {
  if ((f.options.x & kProbeOptionHitCache) == 0u || (f.options.x & kProbeOptionCacheCheck) == 0u)
    return;
  uvec2 e = PROBE_CACHE(i);
  if ((e.y & kHitCacheValid) == 0u) return;
  uint n = PROBE_VOLUME(0u).countsRays.w;  // rays per probe: the same in every volume
  uint perProbe = f.selection.z * n;
  uint g = i / perProbe;
  uint slot = (i % perProbe) / n;
  uint ray = i % n;
  uint c = g / f.counts.y;
  vec3 o = probePosition(f, g);
  bool valid = probeCacheStillValid(f, c, o, probeRotationSlotDirection(slot, ray, n), e);
  if (!valid) PROBE_CACHE(i) = uvec2(0u);
  PROBE_STAT_COUNT(kProbeStatCacheInvalidated, valid ? 0u : 1u);
}
