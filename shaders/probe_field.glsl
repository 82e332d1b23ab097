// The probe field: one DDGI probe volume per SDF cascade (issue 5 items 1-4, 6, 7). Single
// definition of the per-probe classification (scroll reset, SDF relocation, states, hit-cache
// invalidation), the update scheduling, the probe ray (hit cache + stack trace + shading) and
// the cascade-blended irradiance query. GLSL passes include it; gi/probe_field_cpu.cpp includes
// it as C++ inside a struct (the CPU reference, STYLE.md habit 9). Same rules as sdf_trace.glsl.
//
// The includer first includes shaders/shared/{sdf_layout,probe_layout,light_layout,
// color_codec}.h, shaders/sdf_trace.glsl (SDF_CASCADE defined), shaders/probe_math.glsl,
// shaders/light_math.glsl and shaders/probe_update.glsl, and defines
//   PROBE_VOLUME(c)      -> ProbeVolume of cascade c
//   PROBE_DATA(g)        -> vec4 of global probe g: xyz relocation offset (cascade-0 voxels),
//                           w state (kProbe* as float)
//   PROBE_DEPTH(i)       -> vec2 stored depth texel i (already needed by probe_update.glsl)
//   PROBE_CACHE(i)       -> uvec2 hit-cache entry i (trace and classify only)
//   PROBE_ROTATION(r, k) -> vec4 column k of hit-cache rotation slot r (classify only)
//   PROBE_PAGE_CHANGED(c, i) -> bool: page-table entry i of cascade c changed this frame
//   LIGHT_RADIANCE(m)    -> uint RGB9E5 light-cache radiance of material voxel m
//
// Global probe g = cascade * probesPerVolume + s; s is the probe's toroidal storage index in its
// volume: storage coordinate (s % nx, s / nx % ny, s / (nx ny)) holds logical probe
// storage - scroll (wrapped), which sits at originSpacing.xyz + logical * spacing + offset.
//
// Seeds: Majercik et al. 2021 (M21), the Godot SDFGI slides (GS), Hu et al. 2022 SDFDDGI (SDFDDGI).

ivec3 probeStorageCoord(ProbeVolume v, uint s) {
  uint nx = v.countsRays.x;
  uint ny = v.countsRays.y;
  return ivec3(int(s % nx), int((s / nx) % ny), int(s / (nx * ny)));
}

// Toroidal wrap of one axis for values in [-n, 2n) (no % on negative ints: undefined in GLSL).
int probeWrap(int a, int n) {
  int r = a;
  if (r < 0) r += n;
  if (r >= n) r -= n;
  return r;
}

ivec3 probeLogicalCoord(ProbeVolume v, uint s) {
  ivec3 st = probeStorageCoord(v, s);
  return ivec3(probeWrap(st.x - v.scroll.x, int(v.countsRays.x)),
               probeWrap(st.y - v.scroll.y, int(v.countsRays.y)),
               probeWrap(st.z - v.scroll.z, int(v.countsRays.z)));
}

uint probeStorageIndex(ProbeVolume v, ivec3 logical) {
  int x = probeWrap(logical.x + v.scroll.x, int(v.countsRays.x));
  int y = probeWrap(logical.y + v.scroll.y, int(v.countsRays.y));
  int z = probeWrap(logical.z + v.scroll.z, int(v.countsRays.z));
  return uint(x) + v.countsRays.x * (uint(y) + v.countsRays.y * uint(z));
}

uint probeVolumeCount(ProbeVolume v) {
  return v.countsRays.x * v.countsRays.y * v.countsRays.z;
}

vec3 probeGridPosition(ProbeVolume v, ivec3 logical) {
  return vec3(v.originSpacing) + vec3(logical) * v.originSpacing.w;
}

mat3 probeVolumeRotation(ProbeVolume v) {
  return mat3(vec3(v.rayRotationCol0), vec3(v.rayRotationCol1), vec3(v.rayRotationCol2));
}

uint probeStateOf(vec4 data) {
  return uint(data.w + 0.5f);
}

// ---- Hit cache entries (GS "Caching rays": cascade, position and normal of static hits) ----

uvec2 probeCacheEncode(bool hit, float t0, uint cascade, vec3 normal) {
  vec2 o = probeOctEncode(normal) * 0.5f + vec2(0.5f);
  uint ox = uint(clamp(o.x, 0.0f, 1.0f) * 8191.0f + 0.5f);
  uint oy = uint(clamp(o.y, 0.0f, 1.0f) * 8191.0f + 0.5f);
  uint flags = kHitCacheValid | (hit ? kHitCacheHit : 0u);
  return uvec2(floatBitsToUint(t0), flags | (cascade << 2u) | (ox << 6u) | (oy << 19u));
}

vec3 probeCacheNormal(uvec2 e) {
  vec2 o = vec2(float((e.y >> 6u) & 8191u), float((e.y >> 19u) & 8191u)) * (1.0f / 8191.0f);
  return probeOctDecode(o * 2.0f - vec2(1.0f));
}

uint probeCacheCascade(uvec2 e) {
  return (e.y >> 2u) & 7u;
}

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
    if (s.resident) r.gradient = sdfNormal(p, cp.toroidal);
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

// Probe history (uvec4): xyz mean irradiance at the last check (float bits); w packs
// quiet updates (bits 0..7), vigilant frames left (8..15), frames since last update (16..30),
// and bit 31: more than a quarter of its last rays hit backfaces (it sits inside geometry).
uint probeHistoryQuiet(uvec4 h) { return h.w & 255u; }
uint probeHistoryVigilant(uvec4 h) { return (h.w >> 8u) & 255u; }
uint probeHistoryAge(uvec4 h) { return (h.w >> 16u) & 32767u; }
bool probeHistoryInside(uvec4 h) { return (h.w >> 31u) != 0u; }
uvec4 probeHistoryPack(vec3 mean, uint quiet, uint vigilant, uint age, bool inside) {
  return uvec4(floatBitsToUint(mean.x), floatBitsToUint(mean.y), floatBitsToUint(mean.z),
               min(quiet, 255u) | (min(vigilant, 255u) << 8u) | (min(age, 32767u) << 16u) |
                   (inside ? 0x80000000u : 0u));
}

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
// coarser cascades); vigilant while the vigilant countdown runs; sleeping after 4 quiet updates.
uint probeState(ProbeFrame f, ProbeSdf sdf, float spacing, uvec4 history) {
  if ((f.options.x & kProbeOptionStates) == 0u)
    return probeHistoryVigilant(history) > 0u ? kProbeVigilant : kProbeAwake;
  if (sdf.resident && sdf.distance < 0.0f) return kProbeOff;
  if (probeHistoryInside(history)) return kProbeOff;  // M21 Sec. 5: mostly backface hits
  if (!sdf.resident && sdf.distance >= 2.0f * spacing) return kProbeOff;
  if (probeHistoryVigilant(history) > 0u) return kProbeVigilant;
  return probeHistoryQuiet(history) >= 4u ? kProbeSleeping : kProbeAwake;
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

// ---- Scheduling (M21 Sec. 5; GS "Reducing update frequency on invisible probes") -------------

// Priority class of a probe this frame, or kProbeClassNone. Vigilant first; awake probes near the
// camera or in its view cone next; awake probes outside it every second frame; sleeping probes
// every sleepPeriod frames (staggered by probe so the load is even); probes waiting 32 frames or
// more jump to the front.
uint probeUpdateClass(ProbeFrame f, uint g, uint state, vec3 position, float spacing, uint age) {
  if (state == kProbeOff) return kProbeClassNone;
  if (state == kProbeVigilant) return 0u;
  uint frame = f.options.y;
  uint cls = kProbeClassNone;
  if (state == kProbeSleeping) {
    uint period = max(f.options.z, 1u);
    if ((frame + g) % period == 0u) cls = 3u;
  } else {
    vec3 toProbe = position - vec3(f.camera);
    float dist = length(toProbe);
    bool near = dist < 2.0f * spacing;
    bool inView = dist > 0.0f && dot(toProbe / dist, vec3(f.view)) >= f.camera.w;
    if (near || inView) cls = 1u;
    else if (((frame + g) & 1u) == 0u) cls = 2u;
  }
  if (age >= 32u) cls = 0u;
  return cls;
}

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
    if ((f.options.x & kProbeOptionNoChebyshev) == 0u)
      w *= probeChebyshevWeight(probeSampleDepth(probe, dirFromProbe), r, v.visibility.w);
    if (sdfVisibility) w *= probeSdfVisibility(f, c, p, biased);
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

// ---- Tracing and shading a probe ray (issue 5 items 3-5) -------------------------------------

struct ProbeRayHit {
  bool hit;
  float t0;        // cascade-0 voxels
  uint cascade;
  vec3 normal;
  uint material;   // slot * 512 + cell
  bool cacheable;  // a full, final answer (no fallback over a missing page, no step cap)
  uint steps;
};

// The hit of a ray from the cache entry's t and cascade (material re-read at the position,
// normal from the entry). Returns hit = false with cacheable = false when the page is gone.
ProbeRayHit probeHitFromCache(vec3 o, vec3 dir, uvec2 e) {
  ProbeRayHit r;
  r.hit = (e.y & kHitCacheHit) != 0u;
  r.t0 = uintBitsToFloat(e.x);
  r.cascade = probeCacheCascade(e);
  r.normal = probeCacheNormal(e);
  r.material = 0u;
  r.cacheable = true;
  r.steps = 0u;
  if (!r.hit) return r;
  CascadeTraceParams ch = SDF_CASCADE(r.cascade);
  vec3 p = (o + dir * r.t0 - vec3(ch.offsetScale.x, ch.offsetScale.y, ch.offsetScale.z)) / ch.offsetScale.w;
  ivec3 page = sdfPageOf(p);
  uint entry = SDF_PAGE(sdfPageIndex(page, ch.toroidal));
  if ((entry & kPageResidentBit) == 0u) {
    r.hit = false;
    r.cacheable = false;
    return r;
  }
  ivec3 cellXyz = clamp(ivec3(floor(p - vec3(page) * 8.0f)), ivec3(0), ivec3(7));
  r.material = (entry & kPagePayloadMask) * kBrickMaterialCount +
               uint(cellXyz.x + 8 * (cellXyz.y + 8 * cellXyz.z));
  return r;
}

ProbeRayHit probeTraceFresh(ProbeFrame f, uint c, vec3 o, vec3 dir) {
  SdfStackResult s = sdfTraceStackFrom(o, dir, 0.0f, f.trace.w, f.options.w, f.trace.x, c,
                                       f.counts.x);
  ProbeRayHit r;
  r.hit = s.r.hit;
  r.t0 = s.t0;
  r.cascade = s.cascade;
  r.normal = vec3(0.0f, 1.0f, 0.0f);
  r.material = s.r.slot * kBrickMaterialCount + s.r.cell;
  r.cacheable = !s.fellBack && !s.r.ranOutOfSteps && !s.r.missingData;
  r.steps = s.steps;
  if (r.hit) r.normal = sdfNormal(s.r.position, SDF_CASCADE(s.cascade).toroidal);
  return r;
}

// Radiance and depth of a probe ray given its hit (M21 Sec. 2.3, 4.1):
//  - miss: the sky, depth = the volume's max depth;
//  - backface hit (the probe sees the inside of geometry): black, depth shortened;
//  - front hit: the light cache's radiance (emission + direct light, shaders/light_math.glsl)
//    plus albedo * bounceGain * E(n) / pi with E the field's irradiance at the hit from the
//    previous update (multi-bounce feedback).
vec4 probeShadeRay(ProbeFrame f, ProbeVolume v, vec3 o, vec3 dir, ProbeRayHit h) {
  float maxDepth = v.blend.z;
  if (!h.hit) {
    GpuSky sky;
    sky.zenith = f.skyZenith;
    sky.horizon = f.skyHorizon;
    return vec4(skyRadiance(sky, dir), maxDepth);
  }
  bool backface = dot(h.normal, dir) > 0.0f;
  float depth = probeRayDepth(h.t0, true, backface, maxDepth, v.visibility.z);
  // Backface depths are stored negated so the blend can count them; moments use |depth|.
  if (backface) return vec4(0.0f, 0.0f, 0.0f, -depth);
  vec3 albedo = probeSrgbToLinear(vec3(unpackAlbedo(SDF_ALBEDO(h.material))));
  vec3 direct = unpackRgb9e5(LIGHT_RADIANCE(h.material));
  vec3 hitPos = o + dir * h.t0;
  vec3 indirect = probeFieldIrradiance(f, hitPos, h.normal, -dir, false, -1);
  return vec4(direct + albedo * indirect * (f.skyZenith.w * 0.3183098861837907f), depth);
}

#ifdef OBJ_FRAME
// Whether rays of cascade-c probes may meet an object: objects are bound and some region
// cascade >= c lists one (bits of options.x from kProbeObjectMaskShift). Otherwise the trace is
// exactly the static-only path (issue 7 item 5).
bool probeObjectsReach(ProbeFrame f, uint c) {
  if ((f.options.x & kProbeOptionObjects) == 0u) return false;
  uint mask = (f.options.x >> kProbeObjectMaskShift) & 15u;
  return (mask >> min(c, 31u)) != 0u;
}

// A probe ray that hit a moving object first. Until cards exist (issue 7 item 6) the object is
// shaded from its material and the probes: emission + albedo/π · E(hit, n) of the previous
// update (bounce gain applied), with no direct light of its own (docs/DECISIONS.md). Backfaces
// (a probe inside or touching an object) count as in probeShadeRay.
vec4 probeShadeObjectHit(ProbeFrame f, ProbeVolume v, vec3 o, vec3 dir, ObjectHit oh) {
  float maxDepth = v.blend.z;
  bool backface = dot(oh.normal, dir) > 0.0f;
  float depth = probeRayDepth(oh.t, true, backface, maxDepth, v.visibility.z);
  if (backface) return vec4(0.0f, 0.0f, 0.0f, -depth);
  vec3 albedo = probeSrgbToLinear(vec3(unpackAlbedo(oh.albedo)));
  vec3 emission = unpackRgb9e5(oh.emission);
  vec3 hitPos = o + dir * oh.t;
  vec3 indirect = probeFieldIrradiance(f, hitPos, oh.normal, -dir, false, -1);
  return vec4(emission + albedo * indirect * (f.skyZenith.w * 0.3183098861837907f), depth);
}
#endif

// ---- Pass bodies (one call per GPU invocation; the CPU reference loops over the same) --------
// Extra macros for these (the includer defines them as lvalues / atomics):
//   PROBE_HISTORY(g)        -> uvec4 history of global probe g (probeHistoryPack)
//   PROBE_LIST(i)           -> uint global probe at position i of this frame's update list
//   PROBE_RAY(i)            -> vec4 ray result i (list position * raysPerProbe + ray)
//   PROBE_STAT(i)           -> uint frame statistic i (kProbeStat*), read
//   PROBE_STAT_ADD(i, v)    -> atomic add, returns the previous value

vec3 probeMeanIrradiance(uint probe, float gamma) {
  vec3 sum = vec3(0.0f);
  for (uint y = 1u; y <= kProbeIrradianceInterior; ++y)
    for (uint x = 1u; x <= kProbeIrradianceInterior; ++x)
      sum += probeDecodeIrradiance(vec3(PROBE_IRRADIANCE(probeIrradianceIndex(probe, uvec2(x, y)))), gamma);
  return sum * (1.0f / float(kProbeIrradianceInterior * kProbeIrradianceInterior));
}

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
  bool inside = probeHistoryInside(hist);
  vec3 mean = vec3(uintBitsToFloat(hist.x), uintBitsToFloat(hist.y), uintBitsToFloat(hist.z));
  if (entered) {
    for (uint t = 0u; t < kProbeIrradianceTexels * kProbeIrradianceTexels; ++t)
      PROBE_IRRADIANCE(g * kProbeIrradianceTexels * kProbeIrradianceTexels + t) = vec4(0.0f);
    for (uint t = 0u; t < kProbeDepthTexels * kProbeDepthTexels; ++t)
      PROBE_DEPTH(g * kProbeDepthTexels * kProbeDepthTexels + t) = vec2(0.0f);
    quiet = 0u;
    vigilant = f.selection.w;
    age = 0u;
    inside = false;
    mean = vec3(0.0f);
  } else {
    float hLast = vigilant > 0u ? min(v.blend.x, f.view.w) : v.blend.x;
    if ((f.options.x & kProbeOptionLightsChanged) != 0u) {
      vigilant = f.selection.w;
      quiet = 0u;
    }
    if (age == 0u) {  // updated by the previous frame: measure how much it changed
      vec3 now = probeMeanIrradiance(g, v.blend.w);
      vec3 delta = abs(now - mean);
      vec3 top = max(now, mean);
      float change = max(delta.x, max(delta.y, delta.z)) /
                     max(max(top.x, max(top.y, top.z)), 1e-4f);
      // The blend moved the stored mean by (1 - h) of the gap to the update's fresh estimate:
      // judge the gap, not the step, or a high hysteresis would put unconverged probes to sleep.
      float gap = change / max(1.0f - hLast, 1e-3f);
      // Vigilant updates (low hysteresis) are noisy: only calm updates count towards sleep, so
      // a probe never falls asleep holding the noise of its fast-converging phase.
      quiet = gap < f.trace.z && hLast == v.blend.x ? quiet + 1u : 0u;
      if (vigilant > 0u) vigilant -= 1u;
      mean = now;
    }
    age += 1u;
  }
  vec3 offset = vec3(0.0f);
  if ((f.options.x & kProbeOptionRelocation) != 0u)
    offset = probeRelocate(c, f.counts.x, grid, spacing, f.trace.y * spacing);
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
    vigilant = f.selection.w;
    quiet = 0u;
  }
  if (probeObjectsReach(f, c)) insideObject = objInsideAny(grid + offset, c);
#endif
  uvec4 newHist = probeHistoryPack(mean, quiet, vigilant, age, inside);
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
    if (entered || moved) {
      for (uint i = 0u; i < slots * n; ++i) PROBE_CACHE(base + i) = uvec2(0u);
    } else if ((f.options.x & kProbeOptionCacheCheck) != 0u) {
      vec3 o = grid + offset;
      uint dropped = 0u;
      for (uint slot = 0u; slot < slots; ++slot)
        for (uint ray = 0u; ray < n; ++ray) {
          uvec2 e = PROBE_CACHE(base + slot * n + ray);
          if ((e.y & kHitCacheValid) == 0u) continue;
          if (!probeCacheStillValid(f, c, o, probeRotationSlotDirection(slot, ray, n), e)) {
            PROBE_CACHE(base + slot * n + ray) = uvec2(0u);
            dropped += 1u;
          }
        }
      if (dropped > 0u) PROBE_STAT_ADD(kProbeStatCacheInvalidated, dropped);
    }
  }
  PROBE_DATA(g) = vec4(offset, float(state));
  PROBE_HISTORY(g) = newHist;
}

uint probeSelectClass(ProbeFrame f, uint g) {
  uint c = g / f.counts.y;
  ProbeVolume v = PROBE_VOLUME(c);
  vec4 data = PROBE_DATA(g);
  vec3 p = probeGridPosition(v, probeLogicalCoord(v, g % f.counts.y)) + vec3(data);
  return probeUpdateClass(f, g, probeStateOf(data), p, v.originSpacing.w,
                          probeHistoryAge(PROBE_HISTORY(g)));
}

// Which probes of the wanted ones fit this frame's list, from the counts of the count sub-pass
// (every invocation computes the same): x = the first class that does not fit whole
// (kProbeClassCount: all fit); y = the stride k of that class -- its probes with
// (g + frame) % k == 0 are taken, about as many as the room left (0: no room).
uvec2 probeSelectCutoff(ProbeFrame f) {
  uint total = 0u;
  for (uint cls = 0u; cls < kProbeClassCount; ++cls) {
    uint count = PROBE_STAT(kProbeStatClassCounts + cls);
    if (total + count > f.selection.y) {
      uint room = f.selection.y - total;
      uint stride = room == 0u ? 0u : (count + room - 1u) / room;
      return uvec2(cls, stride);
    }
    total += count;
  }
  return uvec2(kProbeClassCount, 0u);
}

// Trace pass body: ray `ray` of the probe at list position l.
void probeTracePass(ProbeFrame f, uint l, uint ray) {
  uint g = PROBE_LIST(l);
  uint c = g / f.counts.y;
  ProbeVolume v = PROBE_VOLUME(c);
  uint n = v.countsRays.w;
  vec3 o = probeGridPosition(v, probeLogicalCoord(v, g % f.counts.y)) + vec3(PROBE_DATA(g));
  vec3 dir = probeRayDirection(ray, n, probeVolumeRotation(v));
  ProbeRayHit h;
  bool useCache = (f.options.x & kProbeOptionHitCache) != 0u;
  uint entry = (g * f.selection.z + uint(v.rayRotationCol0.w)) * n + ray;
  bool cached = false;
  if (useCache) {
    uvec2 e = PROBE_CACHE(entry);
    if ((e.y & kHitCacheValid) != 0u) {
      h = probeHitFromCache(o, dir, e);
      cached = h.cacheable;
    }
  }
  if (cached) {
    PROBE_STAT_ADD(kProbeStatRaysCached, 1u);
  } else {
    h = probeTraceFresh(f, c, o, dir);
    PROBE_STAT_ADD(kProbeStatRaysTraced, 1u);
    PROBE_STAT_ADD(kProbeStatSteps, h.steps);
    if (useCache)
      PROBE_CACHE(entry) = h.cacheable ? probeCacheEncode(h.hit, h.t0, h.cascade, h.normal) : uvec2(0u);
  }
  vec4 shaded;
#ifdef OBJ_FRAME
  // Moving objects (issue 7 item 4; GS slides b, "Combining with Static Lighting"): the dynamic
  // DDA+SDF search runs only up to the static hit, cached or fresh, so static work is never
  // repeated and the hit cache keeps holding static answers only.
  if (probeObjectsReach(f, c)) {
    float tObjects = h.hit ? h.t0 : f.trace.w;
    ObjectHit oh = (f.options.x & kProbeOptionObjectsNaive) != 0u
                       ? objTraceAll(o, dir, 0.0f, tObjects)
                       : objTraceRegions(o, dir, 0.0f, tObjects, c);
    PROBE_STAT_ADD(kProbeStatObjectRays, 1u);
    PROBE_STAT_ADD(kProbeStatObjectSteps, oh.steps);
    if (oh.t >= 0.0f) {
      PROBE_STAT_ADD(kProbeStatObjectHits, 1u);
      shaded = probeShadeObjectHit(f, v, o, dir, oh);
    } else {
      shaded = probeShadeRay(f, v, o, dir, h);
    }
  } else {
    shaded = probeShadeRay(f, v, o, dir, h);
  }
#else
  shaded = probeShadeRay(f, v, o, dir, h);
#endif
  PROBE_RAY(l * n + ray) = shaded;
  PROBE_RAY_DIR(l * n + ray) = vec4(dir, 0.0f);
}

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
    PROBE_IRRADIANCE(i) = probeBlendIrradianceTexel(l * n, n, texel, PROBE_IRRADIANCE(i), h,
                                                    v.blend.w, adaptive);
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

// Group counts (x, y, 1) of a pass over `threads` invocations of 64, spread over rows of 16384
// groups like probeInvocation(), written at PROBE_DISPATCH_ARGS(at .. at + 2).
void probeWriteDispatch(uint at, uint threads) {
  uint groups = (threads + 63u) / 64u;
  uint rows = (groups + 16383u) / 16384u;
  PROBE_DISPATCH_ARGS(at) = rows > 1u ? 16384u : groups;
  PROBE_DISPATCH_ARGS(at + 1u) = max(rows, 1u);
  PROBE_DISPATCH_ARGS(at + 2u) = 1u;
}

// Dispatch sizes of the list-driven passes from this frame's list length (one invocation):
// trace (list x rays) at 0, blend (list x 232) at 3, borders (list x 320) at 6.
void probeWriteListDispatches(ProbeFrame f, uint raysPerProbe) {
  uint listed = min(PROBE_STAT(kProbeStatListCount), f.selection.y);
  probeWriteDispatch(0u, listed * raysPerProbe);
  probeWriteDispatch(3u, listed * kProbeBlendTexelsPerProbe);
  probeWriteDispatch(6u, listed * kProbeTileTexelsPerProbe);
}

// Select pass body (mode kProbeSelectModeCount or kProbeSelectModeEmit), one invocation per probe.
void probeSelectPass(ProbeFrame f, uint g, uint mode) {
  uint cls = probeSelectClass(f, g);
  if (cls >= kProbeClassCount) return;
  if (mode == kProbeSelectModeCount) {
    PROBE_STAT_ADD(kProbeStatClassCounts + cls, 1u);
    return;
  }
  uvec2 cutoff = probeSelectCutoff(f);
  if (cls > cutoff.x) return;
  if (cls == cutoff.x && (cutoff.y == 0u || (f.options.y + g) % cutoff.y != 0u)) return;
  uint index = PROBE_STAT_ADD(kProbeStatListCount, 1u);
  // The stride can overshoot the room by a few probes: the list stays bounded, and those few
  // (the only thread-order-dependent choice) wait for the next frame.
  if (index >= f.selection.y) return;
  PROBE_LIST(index) = g;
  uvec4 h = PROBE_HISTORY(g);
  PROBE_HISTORY(g) = uvec4(h.x, h.y, h.z, h.w & 0x8000ffffu);  // age 0: updated this frame
}
