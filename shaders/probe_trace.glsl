// Probe field, trace pass (probe_trace.comp; shaders/probe_field.glsl lists the pass files): one
// probe ray -- hit cache or a fresh trace through the stack -- and its radiance and depth (M21
// Sec. 2.3, 4.1; GS "Caching rays"), multi-bounce through shaders/probe_sample.glsl. Reads and
// writes
//   PROBE_LIST(l), PROBE_VOLUME(c), PROBE_DATA(g), PROBE_CACHE(i), PROBE_STAT_COUNT(i, v)
//   PROBE_RAY(i), PROBE_RAY_DIR(i) -> vec4 ray result / direction i (list position x rays + ray)
//   LIGHT_RADIANCE(m)        -> uint RGB9E5 light-cache radiance of material voxel m
//   SDF_CASCADE(c), SDF_PAGE(i), SDF_ALBEDO(i) and the stack traversal of shaders/sdf_trace.glsl
// after shaders/shared/{light_layout,color_codec}.h and shaders/light_math.glsl (the sky) and,
// with OBJ_FRAME, shaders/object_trace.glsl.

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
  ivec3 page = sdfPageAlong(p, dir);  // the page a fresh trace reads its material from
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
  vec3 albedo = probeSrgbToLinear(vec3(unpackAlbedo(SDF_ALBEDO(h.material))));
  vec3 direct = unpackRgb9e5(LIGHT_RADIANCE(h.material));
  vec3 hitPos = o + dir * h.t0;
  vec3 indirect = probeFieldIrradiance(f, hitPos, h.normal, -dir, false, -1);
  return vec4(direct + albedo * indirect * (f.skyZenith.w * 0.3183098861837907f), depth);
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
    PROBE_STAT_COUNT(kProbeStatRaysCached, 1u);
  } else {
    h = probeTraceFresh(f, c, o, dir);
    PROBE_STAT_COUNT(kProbeStatRaysTraced, 1u);
    PROBE_STAT_COUNT(kProbeStatSteps, h.steps);
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
    PROBE_STAT_COUNT(kProbeStatObjectRays, 1u);
    PROBE_STAT_COUNT(kProbeStatObjectSteps, oh.steps);
    if (oh.t >= 0.0f) {
      PROBE_STAT_COUNT(kProbeStatObjectHits, 1u);
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

