// Sphere tracing through one cascade's page table and brick atlas. This file is the single
// definition of the trace math: trace_rays.comp includes it as GLSL, and gi/cpu_tracer.cpp
// includes it as C++ inside a struct (the CPU reference of the same math, STYLE.md habit 9).
//
// Rules that keep it valid in both languages: no swizzles, no out/inout parameters (return
// structs), float literals with an f suffix, only functions both GLSL and glm provide.
//
// The includer defines, before including:
//   SDF_PAGE(i)       -> uint page-table entry i (0..4095)
//   SDF_DIST_WORD(i)  -> uint word i of the distance atlas (two fp16 per word)
// and, optionally (GLSL passes), where the device holds the same distances by cell as well
// (gi/gpu_stack_scene.h, sdf_layout.h kBrickCornerWords: one load a sample instead of 8):
//   SDF_CELL_CORNERS(i) -> uvec4 cell i of the corner atlas (the pass's one atlas binding holds
//                          either atlas; both buffer blocks alias it). Such a pass reads the
//                          corners where its specialization constant 0, kSdfCellCorners, is
//                          true (below; gpu::ComputePipelinePair makes each variant).
//   SDF_ALBEDO(i)     -> uint RGBA8 of material voxel i of the atlas
//   SDF_EMISSION(i)   -> uint RGB9E5 of material voxel i of the atlas
// and, for the multi-cascade traversal sdfTraceStack only:
//   SDF_CASCADE(c)    -> CascadeTraceParams of cascade c
//
// Space: positions are cascade-relative, in voxels; [0,128)³ is the cascade (sdf_layout.h).
// Empty pages carry a conservative distance bound (see sdf_layout.h), which is how the tracer
// skips empty space (ARCHITECTURE.md: "empty, at least d away"; Godot SDFGI slides, cascades
// store distance so rays can leap through empty space).

#ifdef SDF_CELL_CORNERS
// Which atlas the binding holds, fixed when the pipeline is made: the driver compiles one path.
// A uniform flag kept both in every pass, and that alone cost the sampling pass 26% on the H200
// with nothing traced (docs/GPU_BUDGET.md, "The corner atlas").
layout(constant_id = 0) const bool kSdfCellCorners = false;
#endif

// `precise` forbids the shader compiler from fusing multiply-adds (NVIDIA does by default), so
// the GPU rounds like the CPU reference (built with -ffp-contract=off) and threshold decisions
// (hit or one more step) agree across vendors. C++ has no such qualifier and needs none.
#ifdef __cplusplus
#define SDF_PRECISE
#else
#define SDF_PRECISE precise
#endif

// What each step of sdfTraceWith was (diagnostics: where a trace's steps go). The CPU reference
// counts them by defining SDF_COUNT_STEP(kind) before including this file (gi/cpu_tracer.h,
// TraceStepKinds); the GPU passes compile the counting away.
#ifndef SDF_COUNT_STEP
#define SDF_COUNT_STEP(kind)
#endif
SDF_CONST uint kSdfStepNearSurface = 0u;  // a brick's sample within a voxel of a surface
SDF_CONST uint kSdfStepBand = 1u;         // a brick's sample 1 voxel or more inside the band
SDF_CONST uint kSdfStepClamped = 2u;      // a brick's sample clamped at the band's edge
SDF_CONST uint kSdfStepEmptyPage = 3u;    // a leap across a page without a brick
SDF_CONST uint kSdfStepMissingPage = 4u;  // a page not streamed in yet: the trace stops
SDF_CONST uint kSdfStepKinds = 5u;

struct SdfSample {
  float distance;  // voxels; for a non-resident page, its conservative bound
  bool resident;   // true when the page holds a brick
  bool missing;    // the page is needed but not streamed in yet (kPageMissing)
  uint slot;       // atlas slot when resident
  float exitT;     // non-resident only: ray distance to leave the page (filled by the tracer)
};

// toroidalOffset: xyz = cascade origin brick mod 16, w = first entry of this cascade's page
// table in SDF_PAGE's array (cascade index * 4096 when all cascades share one buffer).
uint sdfPageIndex(ivec3 page, uvec4 toroidalOffset) {
  // Toroidal addressing: page-table entries are stored at (page + origin) mod 16, so scrolling
  // the cascade rewrites only the entering slab (SDFGI slides, "scrolling").
  uint x = (uint(page.x) + toroidalOffset.x) & 15u;
  uint y = (uint(page.y) + toroidalOffset.y) & 15u;
  uint z = (uint(page.z) + toroidalOffset.z) & 15u;
  return toroidalOffset.w + x + 16u * (y + 16u * z);
}

float sdfBrickDistance(uint slot, uint sx, uint sy, uint sz) {
  uint i = sx + 9u * (sy + 9u * sz);
  uint word = SDF_DIST_WORD(slot * 365u + (i >> 1u));
  vec2 pair = unpackHalf2x16(word);
  return (i & 1u) == 0u ? pair.x : pair.y;
}

// Trilinear interpolation of the 9³ samples of one brick at local position q in [0,8]³.
// Where kSdfCellCorners holds, a cell's 8 samples come from the corner atlas in one load
// instead of 8 (see the top of this file): the same fp16 values, so the same result bit for bit.
float sdfBrickTrilinear(uint slot, vec3 q) {
  vec3 c = clamp(q, vec3(0.0f), vec3(7.999f));
  uint x0 = uint(c.x);
  uint y0 = uint(c.y);
  uint z0 = uint(c.z);
  SDF_PRECISE float fx = q.x - float(x0);
  SDF_PRECISE float fy = q.y - float(y0);
  SDF_PRECISE float fz = q.z - float(z0);
  fx = clamp(fx, 0.0f, 1.0f);
  fy = clamp(fy, 0.0f, 1.0f);
  fz = clamp(fz, 0.0f, 1.0f);
  float d000, d100, d010, d110, d001, d101, d011, d111;
#ifdef SDF_CELL_CORNERS
  if (kSdfCellCorners) {
    uvec4 corners = SDF_CELL_CORNERS(slot * kBrickMaterialCount + x0 + 8u * (y0 + 8u * z0));
    vec2 x00 = unpackHalf2x16(corners.x);
    vec2 x10 = unpackHalf2x16(corners.y);
    vec2 x01 = unpackHalf2x16(corners.z);
    vec2 x11 = unpackHalf2x16(corners.w);
    d000 = x00.x;
    d100 = x00.y;
    d010 = x10.x;
    d110 = x10.y;
    d001 = x01.x;
    d101 = x01.y;
    d011 = x11.x;
    d111 = x11.y;
  } else
#endif
  {
    d000 = sdfBrickDistance(slot, x0, y0, z0);
    d100 = sdfBrickDistance(slot, x0 + 1u, y0, z0);
    d010 = sdfBrickDistance(slot, x0, y0 + 1u, z0);
    d110 = sdfBrickDistance(slot, x0 + 1u, y0 + 1u, z0);
    d001 = sdfBrickDistance(slot, x0, y0, z0 + 1u);
    d101 = sdfBrickDistance(slot, x0 + 1u, y0, z0 + 1u);
    d011 = sdfBrickDistance(slot, x0, y0 + 1u, z0 + 1u);
    d111 = sdfBrickDistance(slot, x0 + 1u, y0 + 1u, z0 + 1u);
  }
  SDF_PRECISE float a = d000 + (d100 - d000) * fx;
  SDF_PRECISE float b = d010 + (d110 - d010) * fx;
  SDF_PRECISE float c2 = d001 + (d101 - d001) * fx;
  SDF_PRECISE float d = d011 + (d111 - d011) * fx;
  SDF_PRECISE float e = a + (b - a) * fy;
  SDF_PRECISE float f = c2 + (d - c2) * fy;
  SDF_PRECISE float r = e + (f - e) * fz;
  return r;
}

ivec3 sdfPageOf(vec3 p) {
  return clamp(ivec3(floor(p * 0.125f)), ivec3(0), ivec3(15));
}

// The page a ray at p heading along dir is in: sdfPageOf(p), except where p lies exactly on the
// low face of that page and the ray heads out through it: then the page beyond. A ray that starts
// on a page face, or runs along one (a camera on a page boundary looking along it), sits there
// exactly; in the page behind the face its exit is already behind it, and a page without a
// surface would then never be left (the leap cannot move past the exit it is on).
// Branch-free and without indexing a vector by a variable (which can put it in local memory).
ivec3 sdfPageAlong(vec3 p, vec3 dir) {
  ivec3 page = sdfPageOf(p);
  ivec3 back = ivec3(lessThan(dir, vec3(0.0f))) * ivec3(equal(p, vec3(page) * 8.0f)) *
               ivec3(greaterThan(page, ivec3(0)));
  return page - back;
}

// The sample at p (cascade voxels) read from `page`, which holds p on its box, faces included.
SdfSample sdfSamplePage(vec3 p, ivec3 page, uvec4 toroidalOffset) {
  uint entry = SDF_PAGE(sdfPageIndex(page, toroidalOffset));
  SdfSample s;
  s.exitT = 0.0f;
  s.missing = entry == kPageMissing;
  if ((entry & 0x80000000u) != 0u) {
    s.resident = true;
    s.slot = entry & 0x7fffffffu;
    SDF_PRECISE vec3 q = p - vec3(page) * 8.0f;
    s.distance = sdfBrickTrilinear(s.slot, q);
  } else {
    s.resident = false;
    s.slot = 0u;
    s.distance = s.missing ? 0.0f : float(entry & 0x7fffffffu);
  }
  return s;
}

SdfSample sdfSampleCascade(vec3 p, uvec4 toroidalOffset) {
  return sdfSamplePage(p, sdfPageOf(p), toroidalOffset);
}

// Ray parameter at which the ray leaves the axis-aligned box [lo, hi] (it starts inside).
float sdfBoxExit(vec3 o, vec3 invDir, vec3 lo, vec3 hi) {
  SDF_PRECISE vec3 t0 = (lo - o) * invDir;
  SDF_PRECISE vec3 t1 = (hi - o) * invDir;
  vec3 tFar = max(t0, t1);
  return min(tFar.x, min(tFar.y, tFar.z));
}

// Returns (tEnter, tExit) of the ray against [lo, hi]; tEnter > tExit means no overlap.
vec2 sdfBoxClip(vec3 o, vec3 invDir, vec3 lo, vec3 hi) {
  SDF_PRECISE vec3 t0 = (lo - o) * invDir;
  SDF_PRECISE vec3 t1 = (hi - o) * invDir;
  vec3 tNear = min(t0, t1);
  vec3 tFar = max(t0, t1);
  return vec2(max(tNear.x, max(tNear.y, tNear.z)), min(tFar.x, min(tFar.y, tFar.z)));
}

vec3 sdfSafeInverse(vec3 d) {
  // Avoid inf*0 = NaN in the slab test for axis-parallel rays.
  float big = 1e30f;
  return vec3(abs(d.x) > 1e-12f ? 1.0f / d.x : big, abs(d.y) > 1e-12f ? 1.0f / d.y : big,
              abs(d.z) > 1e-12f ? 1.0f / d.z : big);
}

// Central differences of the cascade SDF at p, half a voxel each side: the gradient, the distance
// at p, the largest second difference |d(p+e) + d(p-e) - 2 d(p)| over the axes, and whether all
// seven samples are resident. A sample that is not resident counts as the distance at p, so a
// hit next to an empty page still gets a sensible gradient.
struct SdfDifferences {
  vec3 gradient;
  float centre;
  float curvature;
  bool resident;
};

SdfDifferences sdfDifferences(vec3 p, uvec4 toroidalOffset) {
  float h = 0.5f;
  SdfSample c = sdfSampleCascade(p, toroidalOffset);
  SdfDifferences r;
  r.gradient = vec3(0.0f);
  r.centre = c.distance;
  r.curvature = 0.0f;
  r.resident = c.resident;
  for (int axis = 0; axis < 3; ++axis) {
    vec3 e = vec3(axis == 0 ? h : 0.0f, axis == 1 ? h : 0.0f, axis == 2 ? h : 0.0f);
    SdfSample a = sdfSampleCascade(p + e, toroidalOffset);
    SdfSample b = sdfSampleCascade(p - e, toroidalOffset);
    float da = a.resident ? a.distance : c.distance;
    float db = b.resident ? b.distance : c.distance;
    r.gradient[axis] = da - db;
    r.curvature = max(r.curvature, abs(da + db - 2.0f * c.distance));
    r.resident = r.resident && a.resident && b.resident;
  }
  return r;
}

// Surface normal at p (cascade voxels), for points on or near a surface.
// Open sheets are stored as shells |d| - 0.5 (world/mesh_to_sdf.h). Where a sheet is not aligned
// with the grid, the trilinear cells next to the shell's surface straddle the kink at the sheet,
// and central differences there tilt the normal by up to ~15 degrees in a pattern that repeats
// with the grid: stripes along every rotated face. kNormalReach voxels farther out along that
// first normal, every cell a difference reads lies on one side of the sheet, where the field is
// the linear distance to the face and its gradient the face's normal (a 2D model of a face turned
// by 10-45 degrees: mean error 6.5-8.5 -> below 0.05 degrees). The far normal is taken only where
// the field there is that of the face p lies on: about kNormalReach farther from a surface than p,
// flat (no second difference above kNormalFlatness voxel) and turned less than ~25 degrees from
// the near normal. Near an edge the field is curved; near a concave corner the far point lies
// nearer the other surface; there the near normal stays.
SDF_CONST float kNormalReach = 1.0f;
SDF_CONST float kNormalFlatness = 0.05f;
SDF_CONST float kNormalAgreement = 0.9f;  // cos of ~25 degrees; the stripes tilt by <= ~15

vec3 sdfNormal(vec3 p, uvec4 toroidalOffset) {
  SdfDifferences near = sdfDifferences(p, toroidalOffset);
  float len = length(near.gradient);
  if (!(len > 1e-8f)) return vec3(0.0f, 1.0f, 0.0f);
  vec3 n = near.gradient / len;
  vec3 q = p + n * kNormalReach;
  // The far samples must be resident and inside the window (no wrapped pages).
  if (min(q.x, min(q.y, q.z)) < 0.5f || max(q.x, max(q.y, q.z)) > 127.5f) return n;
  SdfDifferences far = sdfDifferences(q, toroidalOffset);
  if (!far.resident || far.centre < near.centre + 0.5f * kNormalReach ||
      far.curvature > kNormalFlatness)
    return n;
  float farLen = length(far.gradient);
  if (!(farLen > 1e-8f)) return n;
  vec3 nFar = far.gradient / farLen;
  return dot(n, nFar) > kNormalAgreement ? nFar : n;
}

// The near normal alone: for callers that need a way out of the surface, not a shading normal
// free of the shells' stripes (probe relocation; the light cache's cells, whose light the probes
// see only blurred). Measured on an H100 (Sponza): without the far normal's 7 extra samples the
// classify pass takes 0.053 ms instead of 0.091, the light cache's full relight 2.96 instead of
// 3.07 (docs/GPU_BUDGET.md, "The far normal where it pays").
vec3 sdfNearNormal(vec3 p, uvec4 toroidalOffset) {
  vec3 g = sdfDifferences(p, toroidalOffset).gradient;
  float len = length(g);
  return len > 1e-8f ? g / len : vec3(0.0f, 1.0f, 0.0f);
}

struct SdfTraceResult {
  float t;         // voxels along the ray; -1 on a miss
  vec3 position;   // cascade-relative hit position
  uint slot;       // atlas slot of the hit brick
  uint cell;       // material voxel index inside the brick
  uint steps;
  bool hit;
  bool ranOutOfSteps;
  bool missingData;  // stopped at a page that is not resident yet: the caller falls back to a
                     // coarser cascade from t
};

// How a trace steps and what it calls a hit. Exact traces (every pass but sampling's visibility
// tests) use sdfExactSteps: a sample below hitEpsilon is a hit, steps are 0.9 d. A visibility test
// needs only hit or miss, not where, so sdfVisibilitySteps trades exactness for fewer steps:
//  - the hit threshold grows with the stretch of ray still ahead, epsilonGrowth per voxel up to
//    epsilonMax, so a ray grazing a surface far from its target is called blocked at once instead
//    of crawling past it; within epsilonMax / epsilonGrowth of the target the threshold tapers back
//    to hitEpsilon, so the receiver's own surface never blocks it;
//  - over-relaxed steps (Keinert et al. 2014, "Enhanced Sphere Tracing", Sec. 3.1): step
//    relaxation x 0.9 d and keep the step only if the unbounding spheres of its two ends overlap
//    (then no surface lies in between); otherwise go back and take the plain 0.9 d step.
struct SdfStepRule {
  float hitEpsilon;     // voxels: a sample below this is a hit
  float epsilonGrowth;  // the threshold's growth per voxel of ray still ahead (0: constant)
  float epsilonMax;     // ... up to this many voxels
  float relaxation;     // 1: plain sphere tracing
};

SdfStepRule sdfExactSteps(float hitEpsilon) {
  SdfStepRule rule;
  rule.hitEpsilon = hitEpsilon;
  rule.epsilonGrowth = 0.0f;
  rule.epsilonMax = hitEpsilon;
  rule.relaxation = 1.0f;
  return rule;
}

// Sampling's visibility tests (probe_sample.glsl). Measured on lavapipe's quick views (docs/
// DECISIONS.md, "Visibility tests step by a looser rule"): Sponza 16.4 -> 10.0 steps a test, most
// of the old ones taken within half a voxel of a surface; relMSE a little lower, but the
// Breakfast Room keeps ~1% less light (grazed probes count as hidden).
SdfStepRule sdfVisibilitySteps(float hitEpsilon) {
  SdfStepRule rule;
  rule.hitEpsilon = hitEpsilon;
  rule.epsilonGrowth = 0.125f;
  rule.epsilonMax = 0.25f;
  rule.relaxation = 1.6f;
  return rule;
}

SdfTraceResult sdfTraceWith(vec3 origin, vec3 dir, float tMin, float tMax, uint maxSteps,
                            SdfStepRule rule, uvec4 toroidalOffset) {
  float hitEpsilon = rule.hitEpsilon;
  SdfTraceResult r;
  r.t = -1.0f;
  r.position = vec3(0.0f);
  r.slot = 0u;
  r.cell = 0u;
  r.steps = 0u;
  r.hit = false;
  r.ranOutOfSteps = false;
  r.missingData = false;

  vec3 invDir = sdfSafeInverse(dir);
  vec2 span = sdfBoxClip(origin, invDir, vec3(0.0f), vec3(128.0f));
  float t = max(tMin, span.x);
  float tEnd = min(tMax, span.y);
  // Stay strictly inside the last page when stepping exactly onto the far cascade face.
  tEnd = tEnd - 1e-4f;
  // The last step when it was over-relaxed: the distance it started from and its length.
  bool relaxedStep = false;
  float stepFromDistance = 0.0f;
  float stepLength = 0.0f;
  for (uint i = 0u; i < maxSteps; ++i) {
    if (t > tEnd) return r;
    r.steps = i + 1u;
    SDF_PRECISE vec3 p = origin + dir * t;
    ivec3 page = sdfPageAlong(p, dir);
    SdfSample s = sdfSamplePage(p, page, toroidalOffset);
    if (s.resident) {
      SDF_COUNT_STEP(s.distance < 1.0f                 ? kSdfStepNearSurface
                     : s.distance < kNarrowBand - 0.05f ? kSdfStepBand
                                                        : kSdfStepClamped);
      if (relaxedStep && 0.9f * (stepFromDistance + s.distance) < stepLength) {
        // The spheres leave a gap a surface could hide in: back to the plain step.
        t = t - stepLength + max(0.9f * stepFromDistance, 0.05f);
        relaxedStep = false;
        continue;
      }
      // Written so that the exact rule's constants fold these away (no cost to exact traces).
      float epsilon = rule.epsilonGrowth > 0.0f
                          ? max(hitEpsilon, min(rule.epsilonMax, rule.epsilonGrowth * (tMax - t)))
                          : hitEpsilon;
      if (s.distance < epsilon) {
        // Two Newton steps onto the zero crossing (t += d): the stopping point of a sphere
        // trace depends on where its steps happened to land (anywhere in the last epsilon);
        // the refined t depends only on the surface, so rays traced from different cascade
        // frames agree to ~1e-4 voxel (the hit cache relies on it).
        // Only near the surface (|d| < epsilon): a ray that starts inside geometry stays put.
        for (int k = 0; k < 2; ++k) {
          if (abs(s.distance) >= hitEpsilon || t + s.distance < tMin) break;
          SDF_PRECISE vec3 q = origin + dir * (t + s.distance);
          ivec3 pageQ = sdfPageAlong(q, dir);
          SdfSample sq = sdfSamplePage(q, pageQ, toroidalOffset);
          if (!sq.resident) break;
          t = t + s.distance;
          p = q;
          s = sq;
          page = pageQ;
        }
        r.hit = true;
        r.t = t;
        r.position = p;
        // The material cell of the brick that was read (p may lie on its high face).
        r.slot = s.slot;
        ivec3 cellXyz = clamp(ivec3(floor(p - vec3(page) * 8.0f)), ivec3(0), ivec3(7));
        r.cell = uint(cellXyz.x + 8 * (cellXyz.y + 8 * cellXyz.z));
        return r;
      }
      // Trilinear fp16 distances can slightly overestimate near corners; 0.9 keeps the step
      // conservative without costing many iterations.
      float plain = max(s.distance * 0.9f, 0.05f);
      float relaxed = s.distance * 0.9f * rule.relaxation;
      relaxedStep = rule.relaxation > 1.0f && relaxed > plain;
      stepFromDistance = s.distance;
      stepLength = relaxedStep ? relaxed : plain;
      t += stepLength;
    } else if (s.missing) {
      SDF_COUNT_STEP(kSdfStepMissingPage);
      r.missingData = true;
      r.t = t;
      r.position = p;
      return r;
    } else {
      // No surface inside this page: leap to its far side, or farther when the bound allows.
      SDF_COUNT_STEP(kSdfStepEmptyPage);
      vec3 lo = vec3(page) * 8.0f;
      float exitT = sdfBoxExit(origin, invDir, lo, lo + vec3(8.0f));
      t = max(exitT + 1e-3f, t + s.distance);
      relaxedStep = false;
    }
  }
  r.ranOutOfSteps = true;
  return r;
}

SdfTraceResult sdfTrace(vec3 origin, vec3 dir, float tMin, float tMax, uint maxSteps,
                        float hitEpsilon, uvec4 toroidalOffset) {
  return sdfTraceWith(origin, dir, tMin, tMax, maxSteps, sdfExactSteps(hitEpsilon), toroidalOffset);
}

// Whether a cascade-relative point lies in the window [0, 128]³ (faces included, with a little
// slack for points computed as an exit of a nested window).
bool sdfInsideWindow(vec3 p) {
  float lo = -1e-3f;
  float hi = 128.0f + 1e-3f;
  return p.x >= lo && p.y >= lo && p.z >= lo && p.x <= hi && p.y <= hi && p.z <= hi;
}

#ifdef SDF_CASCADE
// Traversal across the cascade stack: the ray is given in cascade-0 voxel units
// relative to cascade 0's minimum corner. It is traced in the finest cascade that contains it;
// when it leaves that cascade's window, or reaches a page that is not streamed in yet, it carries
// on from the same point in the next coarser cascade ("never wait": missing data costs detail,
// not a stall). SDF_CASCADE(c) must yield the cascade's CascadeTraceParams (sdf_layout.h).
struct SdfStackResult {
  SdfTraceResult r;  // position and t in the hit cascade's units
  float t0;          // hit distance in cascade-0 voxels (-1 on a miss)
  uint cascade;      // cascade of the hit (or where the ray ended)
  uint steps;        // total over all cascades
  bool fellBack;     // a missing page forced a coarser cascade
};

// As sdfTraceStack, but starting in cascade `firstCascade`: a probe of cascade c traces the
// detail of its own cascade and coarser ones only (SDFGI slides, "Overview of tracing light":
// "the ray is sphere traced from the current cascade to upper cascades"). With `descend`, a ray
// that starts outside a finer window (a camera outside cascade 0's window: `render` centres the
// stack on its target) switches to the finer cascade where it enters its window, so it hits the
// finest surface there instead of a coarse level's, which the conservative min-filter dilates
// by up to a coarse voxel (rounded corners). Windows are nested boxes, so a ray enters each at
// most once, and a ray that starts inside cascade firstCascade's window never descends.
SdfStackResult sdfTraceStackWith(vec3 origin0, vec3 dir, float tMin0, float tMax0, uint maxSteps,
                                 SdfStepRule rule, uint firstCascade, uint cascadeCount,
                                 bool descend) {
  SdfStackResult res;
  res.t0 = -1.0f;
  res.cascade = firstCascade;
  res.steps = 0u;
  res.fellBack = false;
  res.r.t = -1.0f;
  res.r.position = vec3(0.0f);
  res.r.slot = 0u;
  res.r.cell = 0u;
  res.r.steps = 0u;
  res.r.hit = false;
  res.r.ranOutOfSteps = false;
  res.r.missingData = false;
  vec3 invDir = sdfSafeInverse(dir);
  float t0 = tMin0;
  uint c = firstCascade;
  // Each pass either moves to a coarser cascade or (descend) to a finer one it has not left.
  for (uint pass = 0u; pass < 2u * kMaxCascades + 1u && c < cascadeCount; ++pass) {
    CascadeTraceParams cp = SDF_CASCADE(c);
    float scale = cp.offsetScale.w;  // cascade voxel / cascade-0 voxel = 2^c
    SDF_PRECISE vec3 o = (origin0 - vec3(cp.offsetScale.x, cp.offsetScale.y, cp.offsetScale.z)) / scale;
    // The ray continues in the finest cascade that holds its current point: a cascade whose
    // window does not (a probe grid overhanging its window) is skipped, never entered later
    // along the ray (the rest of that stretch would otherwise be traced nowhere).
    if (!sdfInsideWindow(o + dir * (t0 / scale))) {
      ++c;
      continue;
    }
    // Descending: stop where the ray enters the first finer window ahead of it.
    float tStop0 = tMax0;
    uint finer = c;
    if (descend) {
      for (uint j = firstCascade; j < c; ++j) {
        CascadeTraceParams cj = SDF_CASCADE(j);
        SDF_PRECISE vec3 oj =
            (origin0 - vec3(cj.offsetScale.x, cj.offsetScale.y, cj.offsetScale.z)) / cj.offsetScale.w;
        vec2 span = sdfBoxClip(oj, invDir, vec3(0.0f), vec3(128.0f));
        float enter0 = span.x * cj.offsetScale.w;
        if (span.x <= span.y && enter0 > t0 && enter0 < tStop0) {
          tStop0 = enter0;
          finer = j;
        }
      }
    }
    uint budget = maxSteps > res.steps ? maxSteps - res.steps : 0u;
    SdfTraceResult r = sdfTraceWith(o, dir, t0 / scale, tStop0 / scale, budget, rule, cp.toroidal);
    res.steps += r.steps;
    res.r = r;
    res.cascade = c;
    if (r.hit) {
      res.t0 = r.t * scale;
      return res;
    }
    if (r.ranOutOfSteps) return res;
    if (r.missingData) {
      res.fellBack = true;
      t0 = r.t * scale;  // continue at the same point, one cascade coarser
      ++c;
      continue;
    }
    // Left the window, reached tMax, or (descending) reached a finer window.
    vec2 span = sdfBoxClip(o, invDir, vec3(0.0f), vec3(128.0f));
    float exitT0 = span.y * scale;
    if (finer != c && tStop0 < exitT0) {
      t0 = max(t0, tStop0);
      c = finer;
      continue;
    }
    if (exitT0 >= tMax0) return res;
    t0 = max(t0, exitT0);
    ++c;
  }
  return res;
}

SdfStackResult sdfTraceStackFrom(vec3 origin0, vec3 dir, float tMin0, float tMax0, uint maxSteps,
                                 float hitEpsilon, uint firstCascade, uint cascadeCount) {
  return sdfTraceStackWith(origin0, dir, tMin0, tMax0, maxSteps, sdfExactSteps(hitEpsilon),
                           firstCascade, cascadeCount, false);
}

// A camera ray: every cascade, descending into finer windows it enters.
SdfStackResult sdfTraceStack(vec3 origin0, vec3 dir, float tMin0, float tMax0, uint maxSteps,
                             float hitEpsilon, uint cascadeCount) {
  return sdfTraceStackWith(origin0, dir, tMin0, tMax0, maxSteps, sdfExactSteps(hitEpsilon), 0u,
                           cascadeCount, true);
}
#endif  // SDF_CASCADE
