// Probe field, trace pass (probe_trace.comp; shaders/probe_field.glsl lists the pass files): one
// probe ray -- hit cache or a fresh trace through the stack -- and its radiance and depth (M21
// Sec. 2.3, 4.1; GS "Caching rays"), multi-bounce through shaders/probe_sample.glsl. Reads and
// writes
//   PROBE_LIST(l), PROBE_VOLUME(c), PROBE_DATA(g), PROBE_CACHE(i), PROBE_STAT_COUNT(i, v)
//   PROBE_RAY(i), PROBE_RAY_DIR(i) -> vec4 ray result / direction i (list position x rays + ray)
//   LIGHT_RADIANCE(m)        -> uint RGB9E5 light-cache radiance of material voxel m
//   LIGHT_BOUNCE_E(m), LIGHT_BOUNCE_WORD(m), LIGHT_BOUNCE_CLAIM(m, old, new) -> bounce cell m
//   PROBE_BOUNCE_WORK(i)     -> uvec4 work item of the bounce passes; PROBE_APPEND(i) -> a slot
//   SDF_CASCADE(c), SDF_PAGE(i), SDF_ALBEDO(i) and the stack traversal of shaders/sdf_trace.glsl
// after shaders/shared/{light_layout,color_codec}.h and shaders/light_math.glsl (the sky) and,
// with OBJ_FRAME, shaders/object_trace.glsl.

// ---- Tracing and shading a probe ray -----------------------------------------------------------

struct ProbeRayHit {
  bool hit;
  float t0;        // cascade-0 voxels
  uint cascade;
  vec3 normal;
  uint material;   // slot * 512 + cell
  bool cacheable;  // a full, final answer (no fallback over a missing page, no step cap)
  uint steps;
  ivec3 page;      // the page (of `cascade`) whose brick holds `material`
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
  r.page = ivec3(0);
  if (!r.hit) return r;
  CascadeTraceParams ch = SDF_CASCADE(r.cascade);
  vec3 p = (o + dir * r.t0 - vec3(ch.offsetScale.x, ch.offsetScale.y, ch.offsetScale.z)) / ch.offsetScale.w;
  ivec3 page = sdfPageAlong(p, dir);  // the page a fresh trace reads its material from
  uint entry = SDF_PAGE(sdfPageIndex(page, ch.toroidal));
  if ((entry & kPageResidentBit) == 0u) {
    r.hit = false;
    r.cacheable = false;
    return r;
  }
  r.page = page;
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
  r.page = sdfPageAlong(s.r.position, dir);  // the bounce pass checks that it holds r.material
  if (r.hit) r.normal = sdfNormal(s.r.position, SDF_CASCADE(s.cascade).toroidal);
  return r;
}

// The multi-bounce term of a front hit with irradiance e there: albedo x bounceGain x E / pi.
vec3 probeBounceTerm(ProbeFrame f, uint material, vec3 e) {
  vec3 albedo = probeSrgbToLinear(vec3(unpackAlbedo(SDF_ALBEDO(material))));
  return albedo * e * (f.skyZenith.w * 0.3183098861837907f);
}

// Radiance and depth of a probe ray given its hit (M21 Sec. 2.3, 4.1):
//  - miss: the sky, depth = the volume's max depth;
//  - backface hit (the probe sees the inside of geometry): no light (the blend leaves it out),
//    depth shortened and stored negated;
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
  vec3 direct = unpackRgb9e5(LIGHT_RADIANCE(h.material));
  vec3 indirect = probeFieldIrradiance(f, o + dir * h.t0, h.normal, -dir, false, -1);
  return vec4(direct + probeBounceTerm(f, h.material, indirect), depth);
}

// ---- Bounce cells --------------------------------------------------------------------------
// Looked up per hit, the multi-bounce term's E weighs the 8 probes of a cage (16 in a cascade
// blend) with their depth moments: at the default most of the trace pass's time went there
// (1.1 ms on the H100 in Sponza, for about a million rays of which a few thousand were traced
// afresh; docs/GPU_BUDGET.md). Many rays hit the same material voxel, and E varies over a probe
// spacing, not a voxel. A bounce cell keeps E at its voxel's surface point (the light cache's:
// centre - n d, shaders/light_math.glsl) for ProbeFrame::bounce.y updates, and a hit whose normal
// agrees with the cell's takes it. Hits that disagree (a thin wall seen from its far side, edges,
// corners) and cells without a surface point look up their own E, as before.
//
// The work is compacted, so that no warp waits on a few lanes' lookups: the trace pass takes a
// fresh cell's E at once. A ray whose cell is stale claims it (the first to get there this
// update lists the cell) and lists itself; probe_bounce.comp then looks the listed cells up, once
// each, and adds the term to the listed rays. A cell's E depends only on the cell and on the
// field as the previous update's blend left it, so the order the rays run in changes nothing: the
// CPU reference gets the same answers.
SDF_CONST float kBounceCellAgreement = 0.9f;  // cos ~25 degrees between hit and cell normals
// A hit's own lookup biases its receiver towards the probe that shot the ray (view = -dir in
// probeSelfShadowBias); a cell serves rays from every side, so it takes view = kBounceCellView n.
// The bias decides how much light a bounce-lit interior gets back, and how much leaks: the
// Breakfast Room (`bench gi`, full mode, relMSE / E/E_ref) with per-hit lookups at -dir 0.0616 /
// 0.956, at 2/3 n 0.0699 / 0.983; with cells at 0.5 / 2/3 / 0.7 / 0.75 / 0.8 n 0.1749 / 1.194,
// 0.0748 / 1.001, 0.0685 / 0.976, 0.0626 / 0.944, 0.0598 / 0.918 (docs/DECISIONS.md).
SDF_CONST float kBounceCellView = 0.75f;

uint probeBounceStamp(ProbeFrame f) {
  return f.bounce.x & 0xffffu;
}

// A cell looked up in its current epoch: epochs of bounce.y updates, offset per cell. Cells
// looked up in the same update (all of them, where the field leaves its young updates) then do
// not all expire together: in Sponza on the H100 they did, and every fourth update looked up
// 273k cells against 68k-105k in the others (the cells pass 0.28 ms against 0.10-0.13).
bool probeBounceFresh(ProbeFrame f, uint word, uint material) {
  if ((word & kBounceCellValid) == 0u) return false;
  uint age = (probeBounceStamp(f) - ((word >> kBounceCellStampShift) & 0xffffu)) & 0xffffu;
  if (age >= f.bounce.y) return false;
  uint phase = ((material * 2654435761u) >> 16u) % f.bounce.y;
  return (f.bounce.x - age + phase) % f.bounce.y + age < f.bounce.y;
}

uint probeBounceNormalEncode(vec3 n) {
  vec2 o = probeOctEncode(n) * 0.5f + vec2(0.5f);
  uint ox = uint(clamp(o.x, 0.0f, 1.0f) * 63.0f + 0.5f);
  uint oy = uint(clamp(o.y, 0.0f, 1.0f) * 63.0f + 0.5f);
  return ox | (oy << 6u);
}

vec3 probeBounceNormalDecode(uint word) {
  vec2 o = vec2(float(word & 63u), float((word >> 6u) & 63u)) * (1.0f / 63.0f);
  return probeOctDecode(o * 2.0f - vec2(1.0f));
}

// Whether a hit with unit normal n takes the (fresh) cell's E.
bool probeBounceAgrees(uint word, vec3 n) {
  return (word & kBounceCellSurface) != 0u &&
         dot(probeBounceNormalDecode(word), n) >= kBounceCellAgreement;
}

uint probeBouncePagePack(uint cascade, ivec3 page) {
  return cascade | (uint(page.x) << 4u) | (uint(page.y) << 8u) | (uint(page.z) << 12u);
}

// probeShadeRay with bounce cells (f.bounce.y > 0): the radiance of ray `rayIndex` (list
// position x rays + ray) without its multi-bounce term where probe_bounce.comp adds it later.
vec4 probeShadeRayCells(ProbeFrame f, ProbeVolume v, vec3 o, vec3 dir, ProbeRayHit h,
                        uint rayIndex) {
  if (!h.hit || dot(h.normal, dir) > 0.0f) return probeShadeRay(f, v, o, dir, h);  // sky, backface
  float depth = probeRayDepth(h.t0, true, false, v.blend.z, v.visibility.z);
  vec3 direct = unpackRgb9e5(LIGHT_RADIANCE(h.material));
  uint word = LIGHT_BOUNCE_WORD(h.material);
  if (probeBounceFresh(f, word, h.material)) {
    if (probeBounceAgrees(word, h.normal))
      return vec4(direct + probeBounceTerm(f, h.material, unpackRgb9e5(LIGHT_BOUNCE_E(h.material))),
                  depth);
  } else if ((word & kBounceCellPending) == 0u) {
    uint claimed = kBounceCellPending | (probeBounceStamp(f) << kBounceCellStampShift);
    if (LIGHT_BOUNCE_CLAIM(h.material, word, claimed) == word)
      PROBE_BOUNCE_WORK(PROBE_APPEND(kProbeStatBounceCells)) =
          uvec4(h.material, probeBouncePagePack(h.cascade, h.page), 0u, 0u);
  }
  uvec2 hit = probeCacheEncode(true, h.t0, h.cascade, h.normal);
  PROBE_BOUNCE_WORK(f.bounce.z + PROBE_APPEND(kProbeStatBounceRays)) =
      uvec4(rayIndex, h.material, hit.x, hit.y);
  return vec4(direct, depth);
}

// probe_bounce.comp, cells: the listed cell i's E at its surface point. A cell whose page no
// longer holds its brick (a fresh trace's hit on a page face can name the neighbour page) or
// whose centre lies outside the surface band keeps no E: its hits look up their own.
void probeBounceCellPass(ProbeFrame f, uint i) {
  uvec4 w = PROBE_BOUNCE_WORK(i);
  uint m = w.x;
  uint cascade = w.y & 15u;
  ivec3 page = ivec3(int((w.y >> 4u) & 15u), int((w.y >> 8u) & 15u), int((w.y >> 12u) & 15u));
  CascadeTraceParams cp = SDF_CASCADE(cascade);
  uint word = kBounceCellValid | (probeBounceStamp(f) << kBounceCellStampShift);
  vec3 e = vec3(0.0f);
  uint entry = SDF_PAGE(sdfPageIndex(page, cp.toroidal));
  if ((entry & kPageResidentBit) != 0u && (entry & kPagePayloadMask) == m / kBrickMaterialCount) {
    vec3 centre = lightCellCentre(page, m % kBrickMaterialCount);
    SdfSample s = sdfSampleCascade(centre, cp.toroidal);
    if (lightSampleIsSurface(s)) {
      vec3 n = sdfNormal(centre, cp.toroidal);
      vec3 p0 = vec3(cp.offsetScale.x, cp.offsetScale.y, cp.offsetScale.z) +
                (centre - n * s.distance) * cp.offsetScale.w;
      e = probeFieldIrradiance(f, p0, n, n * kBounceCellView, false, -1);
      word |= kBounceCellSurface | probeBounceNormalEncode(n);
    }
  }
  LIGHT_BOUNCE_E(m) = packRgb9e5(e);
  LIGHT_BOUNCE_WORD(m) = word;
}

// probe_bounce.comp, rays: the listed ray r's multi-bounce term from its cell where the cell
// agrees. A ray whose cell disagrees (or has no surface point) is listed once more, for
// probeBounceOwnPass: its own lookup weighs 8-16 probes, and run here it kept the whole subgroup
// of cheap additions waiting on it.
void probeBounceRayPass(ProbeFrame f, uint r) {
  uvec4 w = PROBE_BOUNCE_WORK(f.bounce.z + r);
  uint m = w.y;
  uint word = LIGHT_BOUNCE_WORD(m);
  if (!probeBounceAgrees(word, probeCacheNormal(uvec2(w.z, w.w)))) {
    // The cells' list is used up (probe_bounce.comp ran it before): its slots take these.
    PROBE_BOUNCE_WORK(PROBE_APPEND(kProbeStatBounceOwn)) = w;
    return;
  }
  vec4 ray = PROBE_RAY_STORED(w.x);
  PROBE_RAY_STORED(w.x) =
      vec4(vec3(ray) + probeBounceTerm(f, m, unpackRgb9e5(LIGHT_BOUNCE_E(m))), ray.w);
}

// probe_bounce.comp, own lookups: listed ray i's E looked up at its own hit, as probeShadeRay does.
void probeBounceOwnPass(ProbeFrame f, uint i) {
  uvec4 w = PROBE_BOUNCE_WORK(i);
  uint rayIndex = w.x;
  uvec2 hit = uvec2(w.z, w.w);
  uint perProbe = PROBE_VOLUME(0u).countsRays.w;  // every volume has the same rays per probe
  vec3 o = probePosition(f, PROBE_LIST(rayIndex / perProbe));
  vec3 dir = vec3(PROBE_RAY_DIR(rayIndex));
  vec3 e = probeFieldIrradiance(f, o + dir * uintBitsToFloat(hit.x), probeCacheNormal(hit), -dir,
                                false, -1);
  vec4 ray = PROBE_RAY_STORED(rayIndex);
  PROBE_RAY_STORED(rayIndex) = vec4(vec3(ray) + probeBounceTerm(f, w.y, e), ray.w);
}

#ifdef OBJ_FRAME
// A probe ray that hit a moving object first: its direct light and emission come from the
// instance's cards (card_lookup.glsl; GS slides b, "Storing lighting information"), its indirect
// light from the probes as for static hits: cards + albedo · bounceGain · E(hit, n) / π. Where no
// card saw the hit (or the instance has none) it falls back to emission + the probes' term, the
// shading before cards. Backfaces (a probe inside or touching an object) count as in
// probeShadeRay.
vec4 probeShadeObjectHit(ProbeFrame f, ProbeVolume v, vec3 o, vec3 dir, ObjectHit oh) {
  float maxDepth = v.blend.z;
  bool backface = dot(oh.normal, dir) > 0.0f;
  float depth = probeRayDepth(oh.t, true, backface, maxDepth, v.visibility.z);
  if (backface) return vec4(0.0f, 0.0f, 0.0f, -depth);
  vec3 albedo = probeSrgbToLinear(vec3(unpackAlbedo(oh.albedo)));
  vec3 hitPos = o + dir * oh.t;
  CardLookup card = cardLookup(oh.instance, hitPos, oh.normal);
  vec3 direct = card.weight > 0.0f ? card.radiance : unpackRgb9e5(oh.emission);
  vec3 indirect = probeFieldIrradiance(f, hitPos, oh.normal, -dir, false, -1);
  return vec4(direct + albedo * indirect * (f.skyZenith.w * 0.3183098861837907f), depth);
}
#endif

// ---- Pass body (one call per GPU invocation; the CPU reference loops over the same) ----------

// Trace pass body: ray `ray` of the probe at list position l.
void probeTracePass(ProbeFrame f, uint l, uint ray) {
  uint g = PROBE_LIST(l);
  uint c = g / f.counts.y;
  ProbeVolume v = PROBE_VOLUME(c);
  uint n = v.countsRays.w;
  vec3 o = probePosition(f, g);
  uint slot = probeHistorySlot(PROBE_HISTORY(g));
  vec3 dir = probeRotationSlotDirection(slot, ray, n);
  ProbeRayHit h;
  bool useCache = (f.options.x & kProbeOptionHitCache) != 0u;
  uint entry = (g * f.selection.z + slot) * n + ray;
  bool cached = false;
  if (useCache) {
    uvec2 e = PROBE_CACHE(entry);
    if ((e.y & kHitCacheValid) != 0u) {
      h = probeHitFromCache(o, dir, e);
      cached = h.cacheable;
    }
  }
  if (cached) {
    PROBE_STAT_COUNT(kProbeStatRaysCached, 1u);
  } else {
    h = probeTraceFresh(f, c, o, dir);
    PROBE_STAT_COUNT(kProbeStatRaysTraced, 1u);
    PROBE_STAT_COUNT(kProbeStatSteps, h.steps);
    if (useCache)
      PROBE_CACHE(entry) = h.cacheable ? probeCacheEncode(h.hit, h.t0, h.cascade, h.normal) : uvec2(0u);
  }
  vec4 shaded;
  bool cells = f.bounce.y > 0u;
#ifdef OBJ_FRAME
  // Moving objects (GS slides b, "Combining with Static Lighting"): the dynamic
  // DDA+SDF search runs only up to the static hit, cached or fresh, so static work is never
  // repeated and the hit cache keeps holding static answers only.
  if (probeObjectsReach(f, c)) {
    float tObjects = h.hit ? h.t0 : f.trace.w;
    ObjectHit oh = (f.options.x & kProbeOptionObjectsNaive) != 0u
                       ? objTraceAll(o, dir, 0.0f, tObjects)
                       : objTraceRegions(o, dir, 0.0f, tObjects, c);
    PROBE_STAT_COUNT(kProbeStatObjectRays, 1u);
    PROBE_STAT_COUNT(kProbeStatObjectSteps, oh.steps);
    if (oh.t >= 0.0f) {
      PROBE_STAT_COUNT(kProbeStatObjectHits, 1u);
      shaded = probeShadeObjectHit(f, v, o, dir, oh);
    } else {
      shaded = cells ? probeShadeRayCells(f, v, o, dir, h, l * n + ray) : probeShadeRay(f, v, o, dir, h);
    }
  } else {
    shaded = cells ? probeShadeRayCells(f, v, o, dir, h, l * n + ray) : probeShadeRay(f, v, o, dir, h);
  }
#else
  shaded = cells ? probeShadeRayCells(f, v, o, dir, h, l * n + ray) : probeShadeRay(f, v, o, dir, h);
#endif
  PROBE_RAY(l * n + ray) = shaded;
  PROBE_RAY_DIR(l * n + ray) = vec4(dir, 0.0f);
}

