// Direct light for the static voxel light cache: sun, point and spot lights with
// SDF-traced soft shadows, the sky gradient, and the outgoing radiance of one material cell. One
// definition for both languages: light_cache.comp includes it as GLSL, gi/light_cache.cpp as C++
// inside a struct (the CPU reference, STYLE.md habit 9). Same rules as sdf_trace.glsl: no
// swizzles, no out parameters, f-suffixed literals, SDF_PRECISE where rounding decides a branch.
//
// The includer first includes sdf_layout.h, light_layout.h, color_codec.h and sdf_trace.glsl
// (with SDF_PAGE, SDF_DIST_WORD (and optionally SDF_CELL_CORNERS), SDF_ALBEDO, SDF_EMISSION and
// SDF_CASCADE defined). For lightCacheCellRadiance only (the light cache pass), it also defines
//   LIGHT_AT(i)  -> GpuLight i (0 .. lightCount-1)
//
// Units: positions are cascade-0 voxels relative to cascade 0's minimum corner (the stack
// traversal's space); light distances are turned into metres with voxelSize0 for 1/d².
#ifndef SDF_CASCADE
#error "light_math.glsl needs SDF_CASCADE(c) and sdf_trace.glsl included first"
#endif

SDF_CONST float kLightInvPi = 0.3183098861837907f;
// Cells whose centre is farther than this from the surface (in their cascade's voxels) are not
// surface cells: they keep their emission only.
SDF_CONST float kLightSurfaceBand = 1.5f;

float lightSrgbChannelToLinear(float c) {
  return c <= 0.04045f ? c * (1.0f / 12.92f) : pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

// The atlas stores albedo sRGB-encoded (world/color_pack.h); lighting needs it linear.
vec3 lightSrgbToLinear(vec3 c) {
  return vec3(lightSrgbChannelToLinear(c.x), lightSrgbChannelToLinear(c.y),
              lightSrgbChannelToLinear(c.z));
}

// Sky radiance seen along unit direction dir: horizon colour at and below the horizon, blending
// to the zenith colour straight up (+y is world up). Equal colours give a constant sky.
vec3 skyRadiance(GpuSky sky, vec3 dir) {
  return mix(vec3(sky.horizon), vec3(sky.zenith), clamp(dir.y, 0.0f, 1.0f));
}

// Finest cascade whose window contains p0 (cascade-0 voxels); cascadeCount when none does.
uint lightFinestCascade(vec3 p0, uint cascadeCount) {
  for (uint c = 0u; c < cascadeCount; ++c) {
    CascadeTraceParams cp = SDF_CASCADE(c);
    SDF_PRECISE vec3 q = (p0 - vec3(cp.offsetScale)) / cp.offsetScale.w;
    if (q.x >= 0.0f && q.y >= 0.0f && q.z >= 0.0f && q.x < 128.0f && q.y < 128.0f && q.z < 128.0f)
      return c;
  }
  return cascadeCount;
}

struct LightShadowMarch {
  float visibility;  // min of k·d/t so far (1 = nothing came close)
  float t;           // where the march stopped, in this cascade's voxels
  uint steps;
  bool hit;            // an occluder: a resident sample below hitEpsilon
  bool missing;        // reached a page not streamed in yet (go coarser from t)
  bool ranOutOfSteps;  // neither hit nor left
};

// One cascade of the shadow march; the loop is sdfTrace's (same steps, same empty-page leaps),
// plus the penumbra estimate min(k·d/t) (Quilez's soft shadows; Godot SDFGI slides, "Filling the
// light texture with light": "Shadows are sphere traced"). d/t is a ratio, so measuring both in
// this cascade's voxels gives the same value as cascade-0 voxels. Only resident samples inside
// the narrow band feed the estimate: clamped samples (kNarrowBand) and empty-page bounds are
// lower bounds of the distance and would darken rays that pass far from any occluder.
// escapeSelf (coarser cascades only): the ray may begin inside this cascade's coarser, thicker
// copy of the very surface it leaves (a surface near a finer window's edge); samples below
// epsilon within the first two voxels are stepped through until the ray is outside, instead of
// counting as a hit (which drew black lines along every cascade boundary).
LightShadowMarch lightShadowCascade(vec3 origin, vec3 dir, float tMin, float tMax, uint maxSteps,
                                    float hitEpsilon, float k, uvec4 toroidal, bool escapeSelf) {
  LightShadowMarch r;
  r.visibility = 1.0f;
  r.t = tMin;
  r.steps = 0u;
  r.hit = false;
  r.missing = false;
  r.ranOutOfSteps = false;
  vec3 invDir = sdfSafeInverse(dir);
  vec2 span = sdfBoxClip(origin, invDir, vec3(0.0f), vec3(128.0f));
  float t = max(tMin, span.x);
  float tEnd = min(tMax, span.y) - 1e-4f;  // stay inside the last page (as sdfTrace)
  float escapeEnd = escapeSelf ? t + 2.0f : t;
  for (uint i = 0u; i < maxSteps; ++i) {
    r.t = t;
    if (t > tEnd) return r;
    r.steps = i + 1u;
    SDF_PRECISE vec3 p = origin + dir * t;
    ivec3 page = sdfPageAlong(p, dir);  // on a page face: the page the ray heads into
    SdfSample s = sdfSamplePage(p, page, toroidal);
    if (s.resident && s.distance < hitEpsilon && t < escapeEnd) {
      t += max(abs(s.distance), 0.25f);  // still inside the surface being left
      continue;
    }
    escapeEnd = t;  // outside: from here on every surface counts
    if (s.resident) {
      if (s.distance < hitEpsilon) {
        r.hit = true;
        r.visibility = 0.0f;
        return r;
      }
      if (k > 0.0f && t > 0.0f && s.distance < kNarrowBand)
        r.visibility = min(r.visibility, k * s.distance / t);
      t += max(s.distance * 0.9f, 0.05f);
    } else if (s.missing) {
      r.missing = true;
      return r;
    } else {
      vec3 lo = vec3(page) * 8.0f;
      float exitT = sdfBoxExit(origin, invDir, lo, lo + vec3(8.0f));
      t = max(exitT + 1e-3f, t + s.distance);
    }
  }
  r.t = t;
  r.ranOutOfSteps = true;
  return r;
}

// Visibility in [0,1] of the segment origin0 + dir·[tMin0, tMax0] (cascade-0 voxels) through the
// cascade stack: traced in the finest cascade containing its start, then coarser when it leaves
// a window or meets a page not streamed in yet (the walk of sdfTraceStack). 0 on a hit, 1 when
// the ray leaves the stack or reaches tMax0 untouched; in between, the soft penumbra min(k·d/t)
// (k = GpuLight.shape.z; k == 0: hard shadows, 0 or 1 only). A ray that runs out of steps counts
// as blocked: a shadow leaking light through a wall is worse than one slightly too dark, and such
// rays crawl along surfaces, where n·L is small anyway.
// The walk returns its work too: the steps taken over all cascades (the light cache's work census,
// gi/light_cache.h, counts with it).
struct LightShadowStackMarch {
  float visibility;
  uint steps;
  bool blocked;  // a hit or out of steps
};

LightShadowStackMarch lightShadowStackMarch(vec3 origin0, vec3 dir, float tMin0, float tMax0,
                                            uint maxSteps, float hitEpsilon, uint firstCascade,
                                            uint cascadeCount, float k) {
  LightShadowStackMarch m;
  m.visibility = 1.0f;
  m.steps = 0u;
  m.blocked = false;
  float visibility = 1.0f;
  float t0 = tMin0;
  uint steps = 0u;
  bool fellBack = false;  // the previous cascade stopped at a missing page, not at its edge
  for (uint c = firstCascade; c < cascadeCount; ++c) {
    CascadeTraceParams cp = SDF_CASCADE(c);
    float scale = cp.offsetScale.w;  // cascade voxel / cascade-0 voxel = 2^c
    SDF_PRECISE vec3 o = (origin0 - vec3(cp.offsetScale)) / scale;
    uint budget = maxSteps > steps ? maxSteps - steps : 0u;
    // Only a window left within two coarse voxels of the start can put the ray inside the
    // coarser copy of its own surface; farther on, whatever the coarse cascade holds counts.
    bool escape = c > firstCascade && !fellBack && t0 - tMin0 < 2.0f * scale;
    LightShadowMarch r = lightShadowCascade(o, dir, t0 / scale, tMax0 / scale, budget, hitEpsilon,
                                            k, cp.toroidal, escape);
    steps += r.steps;
    m.steps = steps;
    visibility = min(visibility, r.visibility);
    if (r.hit || r.ranOutOfSteps) {
      m.visibility = 0.0f;
      m.blocked = true;
      return m;
    }
    fellBack = r.missing;
    if (r.missing) {
      t0 = r.t * scale;  // same point, one cascade coarser ("never wait")
    } else {
      // Left the window (cascades are nested, so no finer one can contain the ray again).
      vec2 span = sdfBoxClip(o, sdfSafeInverse(dir), vec3(0.0f), vec3(128.0f));
      float exitT0 = span.y * scale;
      if (exitT0 >= tMax0) break;
      t0 = max(t0, exitT0);
    }
  }
  m.visibility = clamp(visibility, 0.0f, 1.0f);
  return m;
}

// As sdfSoftShadowStack, starting in cascade `firstCascade` (a primary hit's own cascade).
float sdfSoftShadowStackFrom(vec3 origin0, vec3 dir, float tMin0, float tMax0, uint maxSteps,
                             float hitEpsilon, uint firstCascade, uint cascadeCount, float k) {
  LightShadowStackMarch m = lightShadowStackMarch(origin0, dir, tMin0, tMax0, maxSteps,
                                                  hitEpsilon, firstCascade, cascadeCount, k);
#ifdef LIGHT_COUNT_MARCH
  LIGHT_COUNT_MARCH(m);  // the CPU's work census (gi/light_cache.h, lightCacheWork)
#endif
  return m.visibility;
}

float sdfSoftShadowStack(vec3 origin0, vec3 dir, float tMin0, float tMax0, uint maxSteps,
                         float hitEpsilon, uint cascadeCount, float k) {
  SDF_PRECISE vec3 start = origin0 + dir * tMin0;
  return sdfSoftShadowStackFrom(origin0, dir, tMin0, tMax0, maxSteps, hitEpsilon,
                                lightFinestCascade(start, cascadeCount), cascadeCount, k);
}

// 0 below edge0, 1 above edge1, smooth in between; unlike GLSL's smoothstep it is defined when
// edge0 >= edge1 (a spot with equal inner and outer cones becomes a hard step).
float lightSmoothWindow(float edge0, float edge1, float x) {
  float w = clamp((x - edge0) / max(edge1 - edge0, 1e-6f), 0.0f, 1.0f);
  return w * w * (3.0f - 2.0f * w);
}

// Irradiance (E, linear RGB) arriving from light l at surface point p0 (cascade-0 voxels) with
// unit normal n, shadow included. Sun: E = I·colour·max(0, n·L). Point: the same / d² (d in
// metres, at least half a voxel so a light inside geometry stays finite), times the window
// (1 - (d/range)^4)² when range > 0 (Frostbite/UE4: smooth, exactly 0 at the range). Spot: point
// times a smooth step from the outer to the inner cone.
//
// The shadow ray starts half a voxel of the finest cascade containing p0 off the surface, along
// n: far enough that trilinear/fp16 noise of the surface it leaves does not count as a hit, and
// never more than half of a wall one finest voxel thick, so it cannot start beyond such a wall
// (a leak the GI would carry indoors).
// The shadow ray from `origin` towards light l: unit direction and length (cascade-0 voxels) --
// the sun's direction until the ray leaves the stack, or straight to a point/spot light. tMax <= 0
// when the origin sits on the light (no ray).
struct LightShadowRay {
  vec3 dir;
  float tMax;
};

LightShadowRay lightShadowRay(GpuLight l, vec3 origin) {
  LightShadowRay r;
  r.dir = normalize(vec3(l.direction));
  r.tMax = 1e9f;  // the sun: until the ray leaves the stack
  if (uint(l.positionType.w + 0.5f) != kLightSun) {
    vec3 delta = vec3(l.positionType) - origin;
    r.tMax = length(delta);
    if (r.tMax > 0.0f) r.dir = delta / r.tMax;
  }
  return r;
}

// As lightIrradiance, with the shadow ray starting at least minOffset (cascade-0 voxels) off
// the surface: a moving object's card texel (card_light.glsl) starts two of its own grid voxels
// out, so its own SDF does not shadow it.
vec3 lightIrradianceOffset(GpuLight l, vec3 p0, vec3 n, float minOffset, float voxelSize0,
                           uint maxSteps, float hitEpsilon, uint cascadeCount) {
  uint type = uint(l.positionType.w + 0.5f);
  vec3 lightPos = vec3(l.positionType);
  vec3 toLight = normalize(vec3(l.direction));
  float attenuation = 1.0f;
  if (type != kLightSun) {
    vec3 delta = lightPos - p0;
    float dist = length(delta);  // voxels
    if (dist <= 0.0f) return vec3(0.0f);
    toLight = delta / dist;
    float metres = max(dist, 0.5f) * voxelSize0;
    attenuation = 1.0f / (metres * metres);
    float range = l.shape.y;
    if (range > 0.0f) {
      float x = metres / range;
      float x2 = x * x;
      float w = clamp(1.0f - x2 * x2, 0.0f, 1.0f);
      attenuation *= w * w;
    }
    if (type == kLightSpot)
      attenuation *= lightSmoothWindow(l.direction.w, l.shape.x, dot(-toLight, vec3(l.direction)));
  }
  float cosine = max(dot(n, toLight), 0.0f);
  float scalar = l.colorIntensity.w * cosine * attenuation;
  if (!(scalar > 0.0f)) return vec3(0.0f);  // facing away, outside the cone or the range
  if (l.shape.w > 0.5f && cascadeCount > 0u) {
    uint c = lightFinestCascade(p0, cascadeCount);
    float voxel = SDF_CASCADE(c < cascadeCount ? c : cascadeCount - 1u).offsetScale.w;
    SDF_PRECISE vec3 origin = p0 + n * max(0.5f * voxel, minOffset);
    LightShadowRay ray = lightShadowRay(l, origin);
    if (ray.tMax <= 0.0f) return vec3(0.0f);
    scalar *= sdfSoftShadowStack(origin, ray.dir, 0.0f, ray.tMax, maxSteps, hitEpsilon,
                                 cascadeCount, l.shape.z);
#ifdef OBJ_FRAME
    // Moving objects cast hard shadows; the includer binds them.
    if (scalar > 0.0f && OBJ_FRAME.counts.x > 0u && objOccluded(origin, ray.dir, 0.0f, ray.tMax))
      scalar = 0.0f;
#endif
  }
  return vec3(l.colorIntensity) * scalar;
}

vec3 lightIrradiance(GpuLight l, vec3 p0, vec3 n, float voxelSize0, uint maxSteps, float hitEpsilon,
                     uint cascadeCount) {
  return lightIrradianceOffset(l, p0, n, 0.0f, voxelSize0, maxSteps, hitEpsilon, cascadeCount);
}

// Cascade-space page coordinate (0..15 per axis) held by toroidal page-table entry `entry`
// (0..4095) of a cascade with this toroidal offset (the inverse of sdfPageIndex).
ivec3 lightPageOfEntry(uint entry, uvec4 toroidal) {
  uint x = ((entry & 15u) - toroidal.x) & 15u;
  uint y = (((entry >> 4u) & 15u) - toroidal.y) & 15u;
  uint z = (((entry >> 8u) & 15u) - toroidal.z) & 15u;
  return ivec3(int(x), int(y), int(z));
}

// Centre of material cell `cell` (0..511, x fastest) of `page`, in its cascade's voxels.
vec3 lightCellCentre(ivec3 page, uint cell) {
  vec3 local = vec3(float(cell & 7u), float((cell >> 3u) & 7u), float(cell >> 6u));
  return vec3(page) * 8.0f + local + vec3(0.5f);
}

// A cell whose centre sample is resident and within kLightSurfaceBand of the surface: the cells
// lightCacheCellRadiance lights; every other cell holds its emission only.
bool lightSampleIsSurface(SdfSample s) {
  return s.resident && abs(s.distance) <= kLightSurfaceBand;
}

bool lightCellIsSurface(uint cascade, ivec3 page, uint cell) {
  return lightSampleIsSurface(sdfSampleCascade(lightCellCentre(page, cell), SDF_CASCADE(cascade).toroidal));
}

#ifdef LIGHT_AT
// Outgoing Lambertian radiance of material cell `cell` of the resident page `page` of cascade
// `cascade` held in atlas slot `slot`: emission + albedo/π · Σ lightIrradiance, the lights
// evaluated at the surface point nearest the cell centre (centre - n·d, the cascade's SDF d and
// normal n there). Cells farther than kLightSurfaceBand from the surface keep their emission
// only (Godot SDFGI slides, "Filling the light texture with light": every element, every light,
// sphere-traced shadows). The sky is not added: probe rays that miss see it already.
vec3 lightCacheCellRadiance(uint cascade, ivec3 page, uint slot, uint cell, uint lightCount,
                            float voxelSize0, uint maxSteps, float hitEpsilon, uint cascadeCount) {
  uint m = slot * kBrickMaterialCount + cell;
  vec3 emission = unpackRgb9e5(SDF_EMISSION(m));
  if (lightCount == 0u) return emission;
  CascadeTraceParams cp = SDF_CASCADE(cascade);
  vec3 centre = lightCellCentre(page, cell);
  SdfSample s = sdfSampleCascade(centre, cp.toroidal);
  if (!lightSampleIsSurface(s)) return emission;
  vec3 n = sdfNearNormal(centre, cp.toroidal);
  SDF_PRECISE vec3 p = centre - n * s.distance;
  SDF_PRECISE vec3 p0 = vec3(cp.offsetScale) + p * cp.offsetScale.w;
  vec3 irradiance = vec3(0.0f);
  for (uint i = 0u; i < lightCount; ++i)
    irradiance +=
        lightIrradiance(LIGHT_AT(i), p0, n, voxelSize0, maxSteps, hitEpsilon, cascadeCount);
  vec3 albedo = lightSrgbToLinear(vec3(unpackAlbedo(SDF_ALBEDO(m))));
  return emission + albedo * irradiance * kLightInvPi;
}
#endif  // LIGHT_AT
