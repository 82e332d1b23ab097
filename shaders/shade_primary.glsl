// Primary-hit shading of the demo frames: trace one camera ray through the cascade stack and
// return its hit with the hit's outgoing direct radiance (emission + albedo/π · E_direct), or the
// sky radiance on a miss. The indirect term is added by the caller from the probe field
// (GiSystem::irradiance). One definition for both languages (STYLE.md habit 9):
// shade_primary.comp includes it as GLSL, demo/gi_shading.cpp as C++ inside a struct (the CPU
// reference). Same rules as sdf_trace.glsl: no swizzles, no out parameters, f-suffixed literals.
//
// The includer first includes sdf_layout.h, light_layout.h, color_codec.h, shade_layout.h,
// sdf_trace.glsl and light_math.glsl, with SDF_PAGE, SDF_DIST_WORD, SDF_ALBEDO, SDF_EMISSION,
// SDF_CASCADE and
//   LIGHT_AT(i)        -> GpuLight i (0 .. counts.y - 1)
//   LIGHT_RADIANCE(m)  -> uint RGB9E5 light-cache radiance of material voxel m (read only when
//                         options.x == kShadeDirectCache)
// defined.
#if !defined(LIGHT_AT) || !defined(LIGHT_RADIANCE)
#error "shade_primary.glsl needs LIGHT_AT(i), LIGHT_RADIANCE(m) and light_math.glsl included first"
#endif

// The shadow ray of a primary hit (the light cache's rule: half a voxel off the surface along n,
// then sdfSoftShadowStack's walk), with two changes for hits near cascade boundaries, where the
// walk meets coarser cascades right at the surface. The coarse levels are conservative
// (min-filtered: their surface lies outside the fine one), so without them every hit within a
// voxel or two of a window edge reads as shadowed (black lines along every cascade boundary of a
// streamed frame):
//  - the walk starts in the hit's own cascade (not the finest window holding the point), half a
//    voxel of that cascade off the surface, and further out when the hit point lies inside that
//    cascade's surface (a ray that entered a coarser cascade below its inflated surface);
//  - in a coarser cascade entered within two of its voxels of the start, the march first steps
//    out of that cascade's copy of the surface being left (sdfSoftShadowStackFrom).

float shadeSoftShadowStack(vec3 origin0, vec3 dir, float tMax0, uint maxSteps, float hitEpsilon,
                           uint firstCascade, uint cascadeCount, float k) {
  return sdfSoftShadowStackFrom(origin0, dir, 0.0f, tMax0, maxSteps, hitEpsilon, firstCascade,
                                cascadeCount, k);
}

// lightIrradiance (light_math.glsl: cosine, 1/d², range window, spot cone) at hit point p0 of
// cascade hitCascade, times the visibility of the shadow ray above.
vec3 shadeLightIrradiance(GpuLight l, vec3 p0, vec3 n, uint hitCascade, ShadePushConstants pc) {
  GpuLight unshadowed = l;
  unshadowed.shape.w = 0.0f;
  vec3 e = lightIrradiance(unshadowed, p0, n, pc.params.x, 0u, pc.params.z, pc.counts.z);
  if (!(max(e.x, max(e.y, e.z)) > 0.0f) || l.shape.w <= 0.5f || hitCascade >= pc.counts.z)
    return e;
  CascadeTraceParams cp = SDF_CASCADE(hitCascade);
  SdfSample inside = sdfSampleCascade((p0 - vec3(cp.offsetScale)) / cp.offsetScale.w, cp.toroidal);
  float depth = inside.resident ? max(-inside.distance, 0.0f) : 0.0f;
  SDF_PRECISE vec3 origin = p0 + n * ((0.5f + depth) * cp.offsetScale.w);
  vec3 dir = normalize(vec3(l.direction));
  float tMax0 = 1e9f;  // the sun: until the ray leaves the stack
  if (uint(l.positionType.w + 0.5f) != kLightSun) {
    vec3 delta = vec3(l.positionType) - origin;
    tMax0 = length(delta);
    if (tMax0 <= 0.0f) return vec3(0.0f);
    dir = delta / tMax0;
  }
  return e * shadeSoftShadowStack(origin, dir, tMax0, pc.options.y, pc.params.z, hitCascade,
                                  pc.counts.z, l.shape.z);
}

ShadedHit shadePrimary(TraceRay ray, ShadePushConstants pc) {
  vec3 origin = vec3(ray.originTMin);
  vec3 dir = vec3(ray.dirTMax);
  SdfStackResult s = sdfTraceStack(origin, dir, ray.originTMin.w, ray.dirTMax.w, pc.counts.w,
                                   pc.params.y, pc.counts.z);
  ShadedHit h;
  h.steps = s.steps;
  h.flags = (s.r.hit ? kHitFlagHit : 0u) | (s.r.ranOutOfSteps ? kHitFlagRanOutOfSteps : 0u) |
            (s.r.missingData ? kHitFlagMissingData : 0u) | (s.fellBack ? kHitFlagFellBack : 0u) |
            (s.cascade << kHitCascadeShift);
  if (!s.r.hit) {
    // Rays that run out of steps or end on data not streamed in yet show the sky too: a frame
    // never waits for streaming, and a hole reads better as sky than as black.
    h.normalT = vec4(0.0f, 0.0f, 0.0f, -1.0f);
    h.direct = vec4(skyRadiance(pc.sky, dir), 0.0f);
    h.albedo = 0u;
    h.emission = 0u;
    return h;
  }
  vec3 n = sdfNormal(s.r.position, SDF_CASCADE(s.cascade).toroidal);
  uint m = s.r.slot * kBrickMaterialCount + s.r.cell;
  h.normalT = vec4(n, s.t0);
  h.albedo = SDF_ALBEDO(m);
  h.emission = SDF_EMISSION(m);
  vec3 radiance = vec3(0.0f);
  if (pc.options.x == kShadeDirectCache) {
    radiance = unpackRgb9e5(LIGHT_RADIANCE(m));
  } else {
    // The hit point itself (within the hit epsilon of the surface, outside it): the shadow ray
    // leaves it half a finest voxel along n, as the light cache's do.
    SDF_PRECISE vec3 p0 = origin + dir * s.t0;
    vec3 irradiance = vec3(0.0f);
    for (uint i = 0u; i < pc.counts.y; ++i)
      irradiance += shadeLightIrradiance(LIGHT_AT(i), p0, n, s.cascade, pc);
    vec3 albedo = lightSrgbToLinear(vec3(unpackAlbedo(h.albedo)));
    radiance = unpackRgb9e5(h.emission) + albedo * irradiance * kLightInvPi;
  }
  h.direct = vec4(radiance, 0.0f);
  return h;
}
