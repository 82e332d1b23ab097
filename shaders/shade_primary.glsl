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
//
// Moving objects: when OBJ_FRAME is defined (object_bindings.glsl, then
// object_trace.glsl before light_math.glsl: the GLSL pass), each primary ray also searches the
// objects, but only up to its static hit (Godot SDFGI slides b, "Combining with Static
// Lighting": the static answer bounds the dynamic search), and every shadow ray, static hit or
// object hit, is also blocked by the objects (hard shadows, as the light cache's). The CPU
// reference (demo/gi_shading.cpp) leaves OBJ_FRAME undefined: it has no objects, and the GPU
// pass with zero instances computes exactly what it does.
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

#ifdef OBJ_FRAME
// objTraceRegions over the part of [tMin, tMax] inside the objects' AABB (pc.objectsMin/Max):
// every instance lies inside it, so the answer is the same, without walking the empty regions
// outside it.
ObjectHit shadeTraceObjects(vec3 o, vec3 d, float tMin, float tMax, ShadePushConstants pc) {
  vec2 span = objBoxClip(o, objSafeInverse(d), vec3(pc.objectsMin), vec3(pc.objectsMax));
  float t0 = max(tMin, span.x);
  float t1 = min(tMax, span.y);
  if (t0 > t1) return objMiss();
  return objTraceRegions(o, d, t0, t1, 0u);
}
#endif

// lightIrradiance (light_math.glsl: cosine, 1/d², range window, spot cone) at hit point p0 of
// cascade hitCascade, times the visibility of the shadow ray above.
// The same with the shadow ray's start given (origin, stack space).
vec3 shadeLightIrradianceFrom(GpuLight l, vec3 p0, vec3 n, vec3 origin, uint hitCascade,
                              ShadePushConstants pc) {
  GpuLight unshadowed = l;
  unshadowed.shape.w = 0.0f;
  vec3 e = lightIrradiance(unshadowed, p0, n, pc.params.x, 0u, pc.params.z, pc.counts.z);
  if (!(max(e.x, max(e.y, e.z)) > 0.0f) || l.shape.w <= 0.5f || hitCascade >= pc.counts.z)
    return e;
  LightShadowRay ray = lightShadowRay(l, origin);
  if (ray.tMax <= 0.0f) return vec3(0.0f);
  float visibility = shadeSoftShadowStack(origin, ray.dir, ray.tMax, pc.options.y, pc.params.z,
                                          hitCascade, pc.counts.z, l.shape.z);
#ifdef OBJ_FRAME
  // Objects cast hard shadows on the static scene (the light cache's rule, light_math.glsl).
  if (visibility > 0.0f && shadeTraceObjects(origin, ray.dir, 0.0f, ray.tMax, pc).t >= 0.0f)
    visibility = 0.0f;
#endif
  return e * visibility;
}

vec3 shadeLightIrradiance(GpuLight l, vec3 p0, vec3 n, uint hitCascade, ShadePushConstants pc) {
  SDF_PRECISE vec3 origin = p0;
  if (hitCascade < pc.counts.z) {
    CascadeTraceParams cp = SDF_CASCADE(hitCascade);
    SdfSample inside =
        sdfSampleCascade((p0 - vec3(cp.offsetScale)) / cp.offsetScale.w, cp.toroidal);
    float depth = inside.resident ? max(-inside.distance, 0.0f) : 0.0f;
    origin = p0 + n * ((0.5f + depth) * cp.offsetScale.w);
  }
  return shadeLightIrradianceFrom(l, p0, n, origin, hitCascade, pc);
}

#ifdef OBJ_FRAME
// How far (cascade-0 voxels) an object hit's shadow ray starts off the object along its normal.
// The object's own SDF is trilinear in its grid and hits below 0.05 grid voxels: a start closer
// than a grid voxel or two could read the surface it leaves as its occluder (speckled
// self-shadowing). One stack voxel is a few grid voxels at the demo's object sizes and keeps
// contact shadows between objects and the ground within a voxel.
SDF_CONST float kShadeObjectShadowOffset = 1.0f;

// Direct light at point p0 on a moving object (stack space, on its surface) with unit normal n:
// lightIrradiance unshadowed (cosine, 1/d², range, cone), times the static soft-shadow walk from
// the finest cascade holding the shadow ray's start, times 0 when an object (itself included,
// beyond the offset) blocks the ray.
vec3 shadeObjectLightIrradiance(GpuLight l, vec3 p0, vec3 n, ShadePushConstants pc) {
  GpuLight unshadowed = l;
  unshadowed.shape.w = 0.0f;
  vec3 e = lightIrradiance(unshadowed, p0, n, pc.params.x, 0u, pc.params.z, pc.counts.z);
  if (!(max(e.x, max(e.y, e.z)) > 0.0f) || l.shape.w <= 0.5f) return e;
  SDF_PRECISE vec3 origin = p0 + n * kShadeObjectShadowOffset;
  LightShadowRay ray = lightShadowRay(l, origin);
  if (ray.tMax <= 0.0f) return vec3(0.0f);
  float visibility = sdfSoftShadowStack(origin, ray.dir, 0.0f, ray.tMax, pc.options.y,
                                        pc.params.z, pc.counts.z, l.shape.z);
  if (visibility > 0.0f && shadeTraceObjects(origin, ray.dir, 0.0f, ray.tMax, pc).t >= 0.0f)
    visibility = 0.0f;
  return e * visibility;
}

// The shaded hit of a primary ray whose nearest hit is object hit oh: emission + albedo/π ·
// E_direct, lit per pixel whatever options.x says (objects have no light-cache voxels).
ShadedHit shadeObjectHit(vec3 origin, vec3 dir, ObjectHit oh, uint staticSteps,
                         ShadePushConstants pc) {
  ShadedHit h;
  h.steps = staticSteps + oh.steps;
  h.flags = kHitFlagHit | kShadeFlagObject;
  h.normalT = vec4(oh.normal, oh.t);
  h.albedo = oh.albedo;
  h.emission = oh.emission;
  SDF_PRECISE vec3 p0 = origin + dir * oh.t;
  vec3 irradiance = vec3(0.0f);
  for (uint i = 0u; i < pc.counts.y; ++i)
    irradiance += shadeObjectLightIrradiance(LIGHT_AT(i), p0, oh.normal, pc);
  vec3 albedo = lightSrgbToLinear(vec3(unpackAlbedo(oh.albedo)));
  h.direct = vec4(unpackRgb9e5(oh.emission) + albedo * irradiance * kLightInvPi, 0.0f);
  return h;
}
#endif  // OBJ_FRAME

ShadedHit shadePrimary(TraceRay ray, ShadePushConstants pc) {
  vec3 origin = vec3(ray.originTMin);
  vec3 dir = vec3(ray.dirTMax);
  SdfStackResult s = sdfTraceStack(origin, dir, ray.originTMin.w, ray.dirTMax.w, pc.counts.w,
                                   pc.params.y, pc.counts.z);
#ifdef OBJ_FRAME
  // Objects only in front of the static hit (or along the whole ray on a miss); regions from
  // cascade 0, as a camera ray sees every cascade's detail.
  ObjectHit oh = shadeTraceObjects(origin, dir, ray.originTMin.w,
                                   s.r.hit ? s.t0 : ray.dirTMax.w, pc);
  if (oh.t >= 0.0f) return shadeObjectHit(origin, dir, oh, s.steps, pc);
#endif
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

// The finest cascade whose window holds point p0 (stack space) with its page streamed in, or
// cascadeCount when none does: where a given surface's shadow ray starts its walk, as a traced
// hit's starts in the cascade that found it.
uint shadeSurfaceCascade(vec3 p0, uint cascadeCount) {
  for (uint c = 0u; c < cascadeCount; ++c) {
    CascadeTraceParams cp = SDF_CASCADE(c);
    SDF_PRECISE vec3 q = (p0 - vec3(cp.offsetScale)) / cp.offsetScale.w;
    if (!sdfInsideWindow(q)) continue;
    if (!sdfSampleCascade(q, cp.toroidal).missing) return c;
  }
  return cascadeCount;
}

// Where a given surface's shadow rays and probe query start: half a voxel of its cascade along
// n, then further out while the SDF there still reads inside or within a quarter voxel of its
// surface. A mesh point does not lie on the SDF's zero set: an open sheet's SDF is a shell about
// a voxel thick around it, coarse cascades are min-filtered so their surface stands proud of the
// mesh, and in a concave corner the mesh point lies inside the other wall's shell. A shadow walk
// started inside would read the surface it leaves as its occluder, and a probe query there sees
// the probes behind the wall (bright lines along every inner edge). Returns the offset along n
// (cascade-0 voxels), negative when the point is still inside four voxels out (a crevice: no
// direct light from shadowed lights, as a traced hit there would not exist).
float shadeSurfaceOffset(vec3 p0, vec3 n, uint cascade, uint cascadeCount) {
  if (cascade >= cascadeCount) return 0.0f;
  CascadeTraceParams cp = SDF_CASCADE(cascade);
  float s = 0.5f;
  for (uint i = 0u; i < 8u; ++i) {
    SDF_PRECISE vec3 q =
        (p0 + n * (s * cp.offsetScale.w) - vec3(cp.offsetScale)) / cp.offsetScale.w;
    SdfSample at = sdfSampleCascade(q, cp.toroidal);
    if (!at.resident || at.distance >= 0.25f) return s * cp.offsetScale.w;
    if (s >= 4.0f) break;
    s = min(s + max(0.25f - at.distance, 0.25f), 4.0f);
  }
  return -s * cp.offsetScale.w;
}

// A pixel whose primary surface is given (kShadePrimaryGiven: a rasterized triangle, its normal
// and material) rather than traced: the same direct light as a traced hit (shadeLightIrradiance:
// the SDF shadow walk from the surface's cascade, started outside the SDF's surface:
// shadeSurfaceOffset), and moving objects in front of it win as they do over a static hit. Nothing
// rasterized: the sky, as a traced miss.
ShadedHit shadeGivenSurface(TraceRay ray, PrimarySurface surface, ShadePushConstants pc) {
  vec3 origin = vec3(ray.originTMin);
  vec3 dir = vec3(ray.dirTMax);
  bool hit = surface.position.w > 0.5f;
#ifdef OBJ_FRAME
  ObjectHit oh = shadeTraceObjects(origin, dir, ray.originTMin.w,
                                   hit ? surface.normalT.w : ray.dirTMax.w, pc);
  if (oh.t >= 0.0f) return shadeObjectHit(origin, dir, oh, 0u, pc);
#endif
  ShadedHit h;
  h.steps = 0u;
  if (!hit) {
    h.flags = 0u;
    h.normalT = vec4(0.0f, 0.0f, 0.0f, -1.0f);
    h.direct = vec4(skyRadiance(pc.sky, dir), 0.0f);
    h.albedo = 0u;
    h.emission = 0u;
    return h;
  }
  SDF_PRECISE vec3 p0 = vec3(surface.position);
  vec3 n = vec3(surface.normalT);
  uint cascade = shadeSurfaceCascade(p0, pc.counts.z);
  h.flags = kHitFlagHit | ((cascade < pc.counts.z ? cascade : 0u) << kHitCascadeShift);
  h.normalT = surface.normalT;
  h.albedo = surface.albedo;
  h.emission = surface.emission;
  float offset = shadeSurfaceOffset(p0, n, cascade, pc.counts.z);
  SDF_PRECISE vec3 shadowOrigin = p0 + n * abs(offset);
  vec3 irradiance = vec3(0.0f);
  for (uint i = 0u; i < pc.counts.y; ++i) {
    GpuLight l = LIGHT_AT(i);
    if (offset < 0.0f && l.shape.w > 0.5f) continue;  // shadowed: the point is in a crevice
    irradiance += shadeLightIrradianceFrom(l, p0, n, shadowOrigin, cascade, pc);
  }
  vec3 albedo = lightSrgbToLinear(vec3(unpackAlbedo(h.albedo)));
  h.direct = vec4(unpackRgb9e5(h.emission) + albedo * irradiance * kLightInvPi, abs(offset));
  return h;
}
