// Rays against moving objects (Godot SDFGI slides b, "Solution: Split into
// smaller SDFs and combine with DDA"): each instance is a rigid/scaled copy of its mesh's local
// SDF (object_layout.h); a ray walks the macro regions of the finest cascade that holds it (DDA
// over 16³-cell regions, empty ones skipped by their count), and inside a non-empty region sphere
// traces every listed instance in its own grid space over the part of the ray inside the region.
// objTraceAll is the brute-force peer (every instance, no regions) the tests compare with.
//
// Single definition for GLSL and C++ (as sdf_trace.glsl: no swizzles, no out parameters, f
// suffixes). Needs SDF_PRECISE (sdf_trace.glsl defines it; so does object_regions.comp). Define
// first:
//   OBJ_FRAME          -> ObjectFrameGpu of this frame
//   OBJ_MESH(m)        -> ObjectMeshGpu m
//   OBJ_INSTANCE(i)    -> ObjectInstanceGpu i
//   OBJ_REGION(i)      -> ObjectRegionGpu i (cascade * 512 + region)
//   OBJ_LIST(i)        -> uvec4 entry i of the region lists (objListEntry: instance index and
//                         its AABB within the region)
//   OBJ_DIST(i)        -> float sample i of the object-SDF atlas (grid voxels)
//   OBJ_MAT(i)         -> uvec2 (albedo RGBA8, emission RGB9E5) of sample i
// Rays are in stack space (cascade-0 voxels from cascade 0's minimum corner), unit direction.

// A walk's work, counted by the C++ reference when it defines OBJ_COUNT(counter) (tests measure
// where a ray's time goes: ObjectWalkCounts); nothing on the GPU.
#ifndef OBJ_COUNT
#define OBJ_COUNT(counter)
#endif

struct ObjectHit {
  float t;        // stack voxels along the ray; < 0: no hit
  uint instance;  // index into OBJ_INSTANCE
  vec3 normal;    // unit, stack space
  uint albedo;    // RGBA8 of the sample nearest to the hit
  uint emission;  // RGB9E5
  uint steps;     // sphere-tracing steps over all instances tried (cost metric)
  uint instancesTried;
};

ObjectHit objMiss() {
  ObjectHit h;
  h.t = -1.0f;
  h.instance = 0u;
  h.normal = vec3(0.0f, 0.0f, 1.0f);
  h.albedo = 0u;
  h.emission = 0u;
  h.steps = 0u;
  h.instancesTried = 0u;
  return h;
}

// Slab test against [lo, hi]: (tEnter, tExit), empty when tEnter > tExit. The object passes keep
// their own copy of the two box helpers so they do not need the static traversal's bindings.
vec2 objBoxClip(vec3 o, vec3 invDir, vec3 lo, vec3 hi) {
  SDF_PRECISE vec3 t0 = (lo - o) * invDir;
  SDF_PRECISE vec3 t1 = (hi - o) * invDir;
  vec3 tNear = min(t0, t1);
  vec3 tFar = max(t0, t1);
  return vec2(max(tNear.x, max(tNear.y, tNear.z)), min(tFar.x, min(tFar.y, tFar.z)));
}

vec3 objSafeInverse(vec3 d) {
  float big = 1e30f;
  return vec3(abs(d.x) > 1e-12f ? 1.0f / d.x : big, abs(d.y) > 1e-12f ? 1.0f / d.y : big,
              abs(d.z) > 1e-12f ? 1.0f / d.z : big);
}

vec3 objAffine(vec4 r0, vec4 r1, vec4 r2, vec3 p) {
  return vec3(dot(vec3(r0.x, r0.y, r0.z), p) + r0.w, dot(vec3(r1.x, r1.y, r1.z), p) + r1.w,
              dot(vec3(r2.x, r2.y, r2.z), p) + r2.w);
}

vec3 objLinear(vec4 r0, vec4 r1, vec4 r2, vec3 v) {
  return vec3(dot(vec3(r0.x, r0.y, r0.z), v), dot(vec3(r1.x, r1.y, r1.z), v),
              dot(vec3(r2.x, r2.y, r2.z), v));
}

float objSample(uint base, uvec3 dims, uint x, uint y, uint z) {
  return OBJ_DIST(base + x + dims.x * (y + dims.y * z));
}

// Trilinear distance (grid voxels) at grid position g, clamped into the grid box.
float objGridDistance(ObjectMeshGpu m, vec3 g) {
  uvec3 dims = uvec3(m.dimsOffset.x, m.dimsOffset.y, m.dimsOffset.z);
  vec3 hi = vec3(float(dims.x) - 1.001f, float(dims.y) - 1.001f, float(dims.z) - 1.001f);
  vec3 c = clamp(g, vec3(0.0f), hi);
  uint x0 = uint(c.x);
  uint y0 = uint(c.y);
  uint z0 = uint(c.z);
  vec3 f = c - vec3(float(x0), float(y0), float(z0));
  uint b = m.dimsOffset.w;
  float d000 = objSample(b, dims, x0, y0, z0);
  float d100 = objSample(b, dims, x0 + 1u, y0, z0);
  float d010 = objSample(b, dims, x0, y0 + 1u, z0);
  float d110 = objSample(b, dims, x0 + 1u, y0 + 1u, z0);
  float d001 = objSample(b, dims, x0, y0, z0 + 1u);
  float d101 = objSample(b, dims, x0 + 1u, y0, z0 + 1u);
  float d011 = objSample(b, dims, x0, y0 + 1u, z0 + 1u);
  float d111 = objSample(b, dims, x0 + 1u, y0 + 1u, z0 + 1u);
  float x00 = mix(d000, d100, f.x);
  float x10 = mix(d010, d110, f.x);
  float x01 = mix(d001, d101, f.x);
  float x11 = mix(d011, d111, f.x);
  return mix(mix(x00, x10, f.y), mix(x01, x11, f.y), f.z);
}

// Signed distance (stack voxels, a lower bound of the true distance outside) from stack point p
// to instance i; the grid box's outside counts as the distance to the box plus the box value.
float objInstanceDistance(uint i, vec3 p) {
  ObjectInstanceGpu inst = OBJ_INSTANCE(i);
  ObjectMeshGpu m = OBJ_MESH(inst.info.x);
  vec3 g = objAffine(inst.gridFromStack[0], inst.gridFromStack[1], inst.gridFromStack[2], p);
  vec3 hi =
      vec3(float(m.dimsOffset.x - 1u), float(m.dimsOffset.y - 1u), float(m.dimsOffset.z - 1u));
  vec3 outside = max(max(-g, g - hi), vec3(0.0f));
  return (objGridDistance(m, g) + length(outside)) * inst.boundsMin.w;
}

// Sphere traces instance i over [t0, t1] of the ray (stack space). The grid distance times the
// instance's stepScale never exceeds the stack-space distance, so steps cannot skip a surface
// (non-uniform scale included); a ray that starts inside the object hits at once. The hit
// carries its t (up to the hit epsilon before the surface) and instance only: the walk keeps
// the nearest of those, and objShadeHit shades that one.
ObjectHit objTraceInstance(uint i, vec3 o, vec3 d, float t0, float t1) {
  ObjectHit h = objMiss();
  ObjectInstanceGpu inst = OBJ_INSTANCE(i);
  ObjectMeshGpu m = OBJ_MESH(inst.info.x);
  vec3 go = objAffine(inst.gridFromStack[0], inst.gridFromStack[1], inst.gridFromStack[2], o);
  vec3 gd = objLinear(inst.gridFromStack[0], inst.gridFromStack[1], inst.gridFromStack[2], d);
  vec3 hi =
      vec3(float(m.dimsOffset.x - 1u), float(m.dimsOffset.y - 1u), float(m.dimsOffset.z - 1u));
  vec2 span = objBoxClip(go, objSafeInverse(gd), vec3(0.0f), hi);
  float t = max(t0, span.x);
  float tEnd = min(t1, span.y);
  if (t > tEnd) return h;
  h.instancesTried = 1u;
  float stepScale = inst.boundsMin.w;
  float eps = OBJ_FRAME.params.y;
  uint maxSteps = uint(OBJ_FRAME.params.z);
  for (uint s = 0u; s < maxSteps; ++s) {
    SDF_PRECISE vec3 g = go + gd * t;
    float dist = objGridDistance(m, g);
    h.steps += 1u;
    if (dist < eps) {
      h.t = t;
      h.instance = i;
      return h;
    }
    t += max(0.9f * dist, 0.02f) * stepScale;
    if (t > tEnd) break;
  }
  return h;
}

// The normal, material and refined t of the hit a walk kept (objTraceInstance's, unshaded), so
// the six gradient samples and the material read are paid once per ray, not per hit found on the
// way. tMin: the ray's start.
ObjectHit objShadeHit(ObjectHit h, vec3 o, vec3 d, float tMin) {
  if (h.t < 0.0f) return h;
  ObjectInstanceGpu inst = OBJ_INSTANCE(h.instance);
  ObjectMeshGpu m = OBJ_MESH(inst.info.x);
  vec3 go = objAffine(inst.gridFromStack[0], inst.gridFromStack[1], inst.gridFromStack[2], o);
  vec3 gd = objLinear(inst.gridFromStack[0], inst.gridFromStack[1], inst.gridFromStack[2], d);
  vec3 hi =
      vec3(float(m.dimsOffset.x - 1u), float(m.dimsOffset.y - 1u), float(m.dimsOffset.z - 1u));
  float t = h.t;
  SDF_PRECISE vec3 g = go + gd * t;
  float dist = objGridDistance(m, g);
  // Normal: the grid gradient carried to stack space (the gradient of d(gridFromStack·p)).
  float e = 0.5f;
  float dx =
      objGridDistance(m, g + vec3(e, 0.0f, 0.0f)) - objGridDistance(m, g - vec3(e, 0.0f, 0.0f));
  float dy =
      objGridDistance(m, g + vec3(0.0f, e, 0.0f)) - objGridDistance(m, g - vec3(0.0f, e, 0.0f));
  float dz =
      objGridDistance(m, g + vec3(0.0f, 0.0f, e)) - objGridDistance(m, g - vec3(0.0f, 0.0f, e));
  vec3 r0 = vec3(inst.gridFromStack[0].x, inst.gridFromStack[0].y, inst.gridFromStack[0].z);
  vec3 r1 = vec3(inst.gridFromStack[1].x, inst.gridFromStack[1].y, inst.gridFromStack[1].z);
  vec3 r2 = vec3(inst.gridFromStack[2].x, inst.gridFromStack[2].y, inst.gridFromStack[2].z);
  vec3 n = r0 * dx + r1 * dy + r2 * dz;
  // One Newton step along the ray onto the zero crossing (d(t) is nearly linear within a voxel of
  // a surface): the hit lands on the surface, not up to eps before it.
  float stepScale = inst.boundsMin.w;
  float slope = dot(vec3(dx, dy, dz), gd);  // grid voxels per stack voxel, × 2e
  if (slope < -1e-4f) h.t = max(tMin, t - clamp(dist * 2.0f * e / slope, -stepScale, stepScale));
  float len = length(n);
  h.normal = len > 1e-12f ? n / len : -d;
  vec3 c = clamp(g + vec3(0.5f), vec3(0.0f), hi);
  uint idx =
      m.dimsOffset.w + uint(c.x) + m.dimsOffset.x * (uint(c.y) + m.dimsOffset.y * uint(c.z));
  uvec2 material = OBJ_MAT(idx);
  h.albedo = material.x;
  h.emission = material.y;
  return h;
}

// Keeps the nearer of two hits; equal distances go to the lower instance index, so the result
// does not depend on the order of a region's list (built with atomics).
ObjectHit objNearer(ObjectHit best, ObjectHit h) {
  uint steps = best.steps + h.steps;
  uint tried = best.instancesTried + h.instancesTried;
  ObjectHit r = best;
  if (h.t >= 0.0f &&
      (best.t < 0.0f || h.t < best.t || (h.t == best.t && h.instance < best.instance)))
    r = h;
  r.steps = steps;
  r.instancesTried = tried;
  return r;
}

// Brute force: every instance whose AABB the ray crosses within [tMin, tMax].
ObjectHit objTraceAll(vec3 o, vec3 d, float tMin, float tMax) {
  ObjectHit best = objMiss();
  vec3 inv = objSafeInverse(d);
  for (uint i = 0u; i < OBJ_FRAME.counts.x; ++i) {
    ObjectInstanceGpu inst = OBJ_INSTANCE(i);
    vec2 span = objBoxClip(o, inv, vec3(inst.boundsMin.x, inst.boundsMin.y, inst.boundsMin.z),
                           vec3(inst.boundsMax.x, inst.boundsMax.y, inst.boundsMax.z));
    float hiT = best.t >= 0.0f ? min(tMax, best.t) : tMax;
    if (max(span.x, tMin) > min(span.y, hiT)) continue;
    best = objNearer(best, objTraceInstance(i, o, d, tMin, hiT));
  }
  return objShadeHit(best, o, d, tMin);
}

// Occupancy sub-cells (object_layout.h): the inclusive sub-cell range [lo, hi] (0..7) of region
// [rLo, rLo + edge] that the stack-space AABB [bmin, bmax] touches (faces included), and the
// 8-bit row mask of x bits lo..hi. Row (y, z) lives in word y / 4 + 2z at bit 8 · (y % 4).
struct ObjSubRange {
  ivec3 lo;
  ivec3 hi;
};

ObjSubRange objSubCellRange(vec3 bmin, vec3 bmax, vec3 rLo, float edge) {
  float sub = edge / float(kSubCellsPerAxis);
  ObjSubRange r;
  r.lo = clamp(ivec3(floor((bmin - rLo) / sub)), ivec3(0), ivec3(7));
  r.hi = clamp(ivec3(floor((bmax - rLo) / sub)), ivec3(0), ivec3(7));
  return r;
}

uint objRowMask(int lo, int hi) { return ((2u << uint(hi)) - 1u) & ~((1u << uint(lo)) - 1u); }

uint objOccupancyWord(int y, int z) { return uint(y / 4 + 2 * z); }
uint objOccupancyShift(int y) { return 8u * uint(y % 4); }

// ObjectRegionGpu::occupiedBounds of a region's occupancy words (row (y, z) of x bits in word
// y / 4 + 2z at bit 8 (y % 4)): the occupied x, y and z as 8-bit masks; 0 when no bit is set.
// Masks, not a packed box, so the fill into host-placed lists can OR them in atomically.
uint objOccupiedBounds(uint occupancy[kOccupancyWords]) {
  uint xs = 0u;
  uint ys = 0u;
  uint zs = 0u;
  for (uint w = 0u; w < kOccupancyWords; ++w) {
    uint word = occupancy[w];
    xs |= word;
    // Bit 7 of each byte (a row of x at one y) set where the byte is nonzero, no carry across.
    uint rows = (((word & 0x7f7f7f7fu) + 0x7f7f7f7fu) | word) & 0x80808080u;
    uint four = ((rows >> 7u) & 1u) | ((rows >> 14u) & 2u) | ((rows >> 21u) & 4u) |
                ((rows >> 28u) & 8u);
    ys |= four << (4u * (w & 1u));
    zs |= (word != 0u ? 1u : 0u) << (w >> 1u);
  }
  xs = (xs | (xs >> 8u) | (xs >> 16u) | (xs >> 24u)) & 0xffu;
  return xs | (ys << 8u) | (zs << 16u);
}

// The occupiedBounds masks of sub-cell range r (objSubCellRange).
uint objSubRangeMasks(ObjSubRange r) {
  return objRowMask(r.lo.x, r.hi.x) | (objRowMask(r.lo.y, r.hi.y) << 8u) |
         (objRowMask(r.lo.z, r.hi.z) << 16u);
}

// Occupied sub-cells in occupancy words 0 .. word - 1 (word 16: the region's whole count): what
// ObjectRegionGpu::rank stores per word (written by the rank pass, which counts them word by word,
// and by the C++ reference).
uint objOccupiedBefore(uint occupancy[kOccupancyWords], uint word) {
  uint n = 0u;
  for (uint w = 0u; w < word; ++w) n += uint(bitCount(occupancy[w]));
  return n;
}

uint objSubCellCount(ObjSubRange r) {
  return uint((r.hi.x - r.lo.x + 1) * (r.hi.y - r.lo.y + 1) * (r.hi.z - r.lo.z + 1));
}

// The sub-cell header index within its region of occupied sub-cell `bit` (object_layout.h):
// the occupied sub-cells before it.
uint objSubRank(uint region, uint bit) {
  uint word = bit >> 5u;
  uint before = (OBJ_REGION(region).rank[word >> 1u] >> (16u * (word & 1u))) & 0xffffu;
  uint below = OBJ_REGION(region).occupancy[word] & ((1u << (bit & 31u)) - 1u);
  return before + uint(bitCount(below));
}

// A region list entry (OBJ_LIST): x is the instance index, y..w its stack AABB within the
// region, so the walk tests a listed instance's box from the entry it has just read instead of a
// second, dependent load of the instance's bounds. Coordinates are in region edges from the
// region's min corner, clamped to [-0.5, 1.5] (a ray's stretch in the region never leaves it by
// more than a hair) and quantised to 16 bits outward with a code of slack (min down, max up), so
// the decoded box holds the true box's part near the region; the instance's own trace clips to
// its grid box, so a looser box costs a test, never a hit. y: lo.x | lo.y << 16,
// z: lo.z | hi.x << 16, w: hi.y | hi.z << 16.
uint objListCode(float u, bool up) {
  float s = (clamp(u, -0.5f, 1.5f) + 0.5f) * 32767.5f;
  return uint(clamp(up ? ceil(s) + 1.0f : floor(s) - 1.0f, 0.0f, 65535.0f));
}

uvec4 objListEntry(uint instance, vec3 bmin, vec3 bmax, vec3 rLo, float edge) {
  vec3 a = (bmin - rLo) / edge;
  vec3 b = (bmax - rLo) / edge;
  return uvec4(instance, objListCode(a.x, false) | (objListCode(a.y, false) << 16u),
               objListCode(a.z, false) | (objListCode(b.x, true) << 16u),
               objListCode(b.y, true) | (objListCode(b.z, true) << 16u));
}

struct ObjListBox {
  vec3 lo;
  vec3 hi;
};

ObjListBox objListEntryBox(uvec4 e, vec3 rLo, float edge) {
  float k = edge / 32767.5f;
  vec3 lo = vec3(float(e.y & 0xffffu), float(e.y >> 16u), float(e.z & 0xffffu));
  vec3 hi = vec3(float(e.z >> 16u), float(e.w & 0xffffu), float(e.w >> 16u));
  ObjListBox b;
  b.lo = rLo + lo * k - vec3(0.5f * edge);
  b.hi = rLo + hi * k - vec3(0.5f * edge);
  return b;
}

// Whether a region grid cascade c holds stack point p (faces included).
bool objInRegionGrid(uint c, vec3 p) {
  vec4 ro = OBJ_FRAME.regionOrigin[c];
  vec3 q = (p - vec3(ro.x, ro.y, ro.z)) / ro.w;
  return q.x >= 0.0f && q.y >= 0.0f && q.z >= 0.0f && q.x <= 8.0f && q.y <= 8.0f && q.z <= 8.0f;
}

// One list entry against the ray's stretch [from, to] of its region: the instance's AABB first
// (from the entry), before its grid maps and any SDF read; a little past `to`, so a surface
// exactly on a face is not lost.
ObjectHit objTestEntry(ObjectHit best, uvec4 entry, vec3 o, vec3 d, vec3 inv, float from, float to,
                       vec3 rLo, float edge) {
  OBJ_COUNT(entriesTested);
  float hiT = best.t >= 0.0f ? min(best.t, to + 1e-3f) : to + 1e-3f;
  ObjListBox lb = objListEntryBox(entry, rLo, edge);
  vec2 box = objBoxClip(o, inv, lb.lo, lb.hi);
  if (max(box.x, from) > min(box.y, hiT)) return best;
  OBJ_COUNT(boxesCrossed);
  return objNearer(best, objTraceInstance(entry.x, o, d, from, hiT));
}

// DDA over the macro regions (finest cascade holding the current point), tracing the instances
// listed in each non-empty region over the ray's stretch inside it. A surface point in region R
// lies inside every listed instance's OBB that contains it, so the first region with a hit holds
// the nearest one. Regions cover the first OBJ_FRAME.counts.y cascades only: beyond them the ray
// sees no objects. Like the static traversal of a probe (sdfTraceStackFrom), a ray uses the
// regions of firstCascade and coarser only, so a coarse probe sees the objects the size rule
// lists for its cascade.
// Inside a region the entries come in runs, each tested over its own stretch of the ray: first
// the wide instances over the whole stretch, then, from a 3D DDA over the region's 8³ sub-cells
// (Amanatides & Woo, at most 22 steps; GS slides b, "Split into smaller SDFs and combine with
// DDA": the bitfield looks up empty cells beforehand, so the DDA never taps into empty space),
// the list of each occupied sub-cell the ray crosses, over the ray's part inside it. Every
// surface point lies in the sub-cell that holds it, inside its instance's AABB, which that
// sub-cell lists: the walk returns at the first sub-cell that holds a hit. Without sub-cell
// lists (kNoSubLists) the first occupied sub-cell's run is every entry after the wide ones (all
// of them in host-placed lists, which put no entry first and mark every instance's sub-cells),
// over the rest of the stretch. One call site of objTestEntry (and so of the inlined sphere
// tracer) keeps the pass's code and registers small.
// anyHit: stop at the first hit found (shadow rays); the nearest one otherwise. Unshaded either
// way (objTraceRegions shades the one it returns).
ObjectHit objWalkRegions(vec3 o, vec3 d, float tMin, float tMax, uint firstCascade, bool anyHit) {
  ObjectHit best = objMiss();
  uint cascades = OBJ_FRAME.counts.y;
  if (OBJ_FRAME.counts.x == 0u || firstCascade >= cascades) return best;
  vec3 inv = objSafeInverse(d);
  // Clip to the coarsest region grid, where anything is listed, and to the box around every
  // instance: most rays of a frame never come near an object and stop here.
  vec4 outer = OBJ_FRAME.regionOrigin[cascades - 1u];
  vec3 outerLo = vec3(outer.x, outer.y, outer.z);
  vec3 lo = max(outerLo, vec3(OBJ_FRAME.boundsMin.x, OBJ_FRAME.boundsMin.y, OBJ_FRAME.boundsMin.z));
  vec3 hi = min(outerLo + vec3(8.0f * outer.w),
                vec3(OBJ_FRAME.boundsMax.x, OBJ_FRAME.boundsMax.y, OBJ_FRAME.boundsMax.z));
  if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return best;
  vec2 span = objBoxClip(o, inv, lo, hi);
  float t = max(tMin, span.x);
  float tEnd = min(tMax, span.y);
  ivec3 stepDir = ivec3(d.x >= 0.0f ? 1 : -1, d.y >= 0.0f ? 1 : -1, d.z >= 0.0f ? 1 : -1);
  OBJ_COUNT(rays);
  for (uint step = 0u; step < 512u && t <= tEnd; ++step) {
    OBJ_COUNT(regionSteps);
    // The finest cascade holding the point a hair past t (the region being entered).
    uint c = cascades - 1u;
    for (uint k = firstCascade; k < cascades; ++k) {
      if (objInRegionGrid(k, o + d * (t + 1e-4f))) {
        c = k;
        break;
      }
    }
    vec4 ro = OBJ_FRAME.regionOrigin[c];
    vec3 lo = vec3(ro.x, ro.y, ro.z);
    vec3 q = (o + d * (t + 1e-4f) - lo) / ro.w;
    ivec3 r = clamp(ivec3(floor(q)), ivec3(0), ivec3(7));
    vec3 rLo = lo + vec3(float(r.x), float(r.y), float(r.z)) * ro.w;
    float exitT = objBoxClip(o, inv, rLo, rLo + vec3(ro.w)).y;
    float segEnd = min(exitT, tEnd);
    uint region = c * 512u + uint(r.x) + 8u * (uint(r.y) + 8u * uint(r.z));
    uint count = OBJ_REGION(region).count;
    if (count > 0u) {
      OBJ_COUNT(listedRegions);
      uint start = OBJ_REGION(region).start;
      uint wide = OBJ_REGION(region).wide;
      uint subBase = OBJ_REGION(region).subBase;
      // The sub-cell DDA, over the ray's part inside the box of the occupied sub-cells, from
      // the sub-cell holding its start.
      float sub = ro.w / float(kSubCellsPerAxis);
      uint ob = OBJ_REGION(region).occupiedBounds;
      uvec3 masks = uvec3(ob & 0xffu, (ob >> 8u) & 0xffu, (ob >> 16u) & 0xffu);
      ivec3 bLo = max(findLSB(masks), ivec3(0));  // no bit (only wide entries): never walked
      ivec3 bHi = max(findMSB(masks), ivec3(0));
      vec2 inBox = objBoxClip(o, inv, rLo + vec3(bLo) * sub, rLo + vec3(bHi + ivec3(1)) * sub);
      float cellT = max(t, inBox.x);
      float walkEnd = min(segEnd, inBox.y);
      ivec3 cell = clamp(ivec3(floor((o + d * cellT - rLo) / sub)), bLo, bHi);
      vec3 tNext = vec3(1e30f);
      vec3 tDelta = vec3(1e30f);
      for (int a = 0; a < 3; ++a) {
        if (abs(d[a]) > 1e-12f) {
          float face = rLo[a] + (float(cell[a]) + (stepDir[a] > 0 ? 1.0f : 0.0f)) * sub;
          tNext[a] = (face - o[a]) / d[a];
          tDelta[a] = sub / abs(d[a]);
        }
      }
      bool walking = count > wide && cellT <= walkEnd;
      bool crossed = false;
      uint ddaSteps = 0u;
      // The first run: the wide entries over the region's stretch. `done`: every surface before
      // it has been tested for, so a hit there is the nearest.
      uint runStart = start;
      uint runCount = wide;
      float runFrom = t;
      float runTo = segEnd;
      float done = t;
      for (uint run = 0u; run < 26u; ++run) {
        for (uint k = 0u; k < runCount; ++k) {
          best = objTestEntry(best, OBJ_LIST(runStart + k), o, d, inv, runFrom, runTo, rLo, ro.w);
          if (anyHit && best.t >= 0.0f) return best;
        }
        if (best.t >= 0.0f && best.t <= done + 1e-3f) return best;
        // The next run: the list of the next occupied sub-cell along the ray.
        runCount = 0u;
        while (walking && runCount == 0u) {
          OBJ_COUNT(occupancySteps);
          float cellExit = min(min(tNext.x, min(tNext.y, tNext.z)), segEnd);
          uint bit = uint(cell.x) + 8u * uint(cell.y) + 64u * uint(cell.z);
          if ((OBJ_REGION(region).occupancy[bit >> 5u] & (1u << (bit & 31u))) != 0u) {
            if (!crossed) {
              OBJ_COUNT(occupiedRegions);
            }
            crossed = true;
            // A hair before the sub-cell's entry: rounding at its face must not skip a surface.
            runFrom = max(t, cellT - 1e-4f * ro.w);
            if (subBase == kNoSubLists) {
              runStart = start + wide;
              runCount = count - wide;
              runTo = segEnd;
              walking = false;
            } else {
              OBJ_COUNT(occupiedCells);
              uvec4 header = OBJ_LIST(subBase + objSubRank(region, bit));
              runStart = header.x;
              runCount = header.y;
              runTo = cellExit;
            }
            done = runTo;
          } else if (best.t >= 0.0f && best.t <= cellExit + 1e-3f) {
            return best;  // a wide instance's hit, and nothing before it
          }
          cellT = cellExit;
          if (tNext.x <= tNext.y && tNext.x <= tNext.z) {
            cell.x += stepDir.x;
            tNext.x += tDelta.x;
          } else if (tNext.y <= tNext.z) {
            cell.y += stepDir.y;
            tNext.y += tDelta.y;
          } else {
            cell.z += stepDir.z;
            tNext.z += tDelta.z;
          }
          ddaSteps += 1u;
          if (cellExit >= walkEnd || ddaSteps >= 24u || any(lessThan(cell, bLo)) ||
              any(greaterThan(cell, bHi)))
            walking = false;
        }
        if (runCount == 0u) break;
      }
    }
    if (best.t >= 0.0f && best.t <= segEnd + 1e-3f) return best;
    t = max(exitT, t + 1e-4f * ro.w);
  }
  return best;
}

ObjectHit objTraceRegions(vec3 o, vec3 d, float tMin, float tMax, uint firstCascade) {
  return objShadeHit(objWalkRegions(o, d, tMin, tMax, firstCascade, false), o, d, tMin);
}

// Whether any object blocks the ray within [tMin, tMax] (the regions of every cascade): the
// walk stops at the first hit, whichever it is, and shades nothing.
bool objOccluded(vec3 o, vec3 d, float tMin, float tMax) {
  return objWalkRegions(o, d, tMin, tMax, 0u, true).t >= 0.0f;
}

// Separating-axis test of an instance's oriented grid box against the axis-aligned stack box
// [lo, hi] (15 axes: the box's 3, the OBB's 3 and their 9 cross products; Gottschalk et al.,
// "OBBTree"). Non-uniform scale keeps the OBB's edges orthogonal (rotation × diagonal), so this is
// exact; faces that touch count as overlapping. The region build (object_regions.comp) and its
// brute-force reference (gi/object_scene_cpu.cpp) both call it.
bool objObbOverlapsBox(ObjectInstanceGpu inst, uvec3 dims, vec3 lo, vec3 hi) {
  vec3 hg = vec3(float(dims.x - 1u), float(dims.y - 1u), float(dims.z - 1u)) * 0.5f;
  vec3 cB = objAffine(inst.stackFromGrid[0], inst.stackFromGrid[1], inst.stackFromGrid[2], hg);
  vec3 a0 = vec3(inst.stackFromGrid[0].x, inst.stackFromGrid[1].x, inst.stackFromGrid[2].x) * hg.x;
  vec3 a1 = vec3(inst.stackFromGrid[0].y, inst.stackFromGrid[1].y, inst.stackFromGrid[2].y) * hg.y;
  vec3 a2 = vec3(inst.stackFromGrid[0].z, inst.stackFromGrid[1].z, inst.stackFromGrid[2].z) * hg.z;
  vec3 hA = (hi - lo) * 0.5f;
  vec3 T = cB - (lo + hi) * 0.5f;
  vec3 axes[15];
  axes[0] = vec3(1.0f, 0.0f, 0.0f);
  axes[1] = vec3(0.0f, 1.0f, 0.0f);
  axes[2] = vec3(0.0f, 0.0f, 1.0f);
  axes[3] = a0;
  axes[4] = a1;
  axes[5] = a2;
  for (uint k = 0u; k < 3u; ++k) {
    axes[6u + k * 3u] = cross(axes[k], a0);
    axes[7u + k * 3u] = cross(axes[k], a1);
    axes[8u + k * 3u] = cross(axes[k], a2);
  }
  for (uint k = 0u; k < 15u; ++k) {
    vec3 L = axes[k];
    float rA = hA.x * abs(L.x) + hA.y * abs(L.y) + hA.z * abs(L.z);
    float rB = abs(dot(a0, L)) + abs(dot(a1, L)) + abs(dot(a2, L));
    // Relative slack: parallel edges give a zero cross product (0 > 0 is false: no separation).
    if (abs(dot(T, L)) > (rA + rB) * 1.0001f + 1e-6f * length(L)) return false;
  }
  return true;
}

// Region range [lo, hi] (inclusive, 0..7) of cascade c that an instance's AABB overlaps; lo > hi
// on some axis when it misses the cascade's region grid. Also applies the size rule.
struct ObjRegionRange {
  ivec3 lo;
  ivec3 hi;
  bool any;
};

ObjRegionRange objRegionRange(ObjectInstanceGpu inst, uint c) {
  ObjRegionRange rr;
  vec4 ro = OBJ_FRAME.regionOrigin[c];
  vec3 o = vec3(ro.x, ro.y, ro.z);
  vec3 bmin = (vec3(inst.boundsMin.x, inst.boundsMin.y, inst.boundsMin.z) - o) / ro.w;
  vec3 bmax = (vec3(inst.boundsMax.x, inst.boundsMax.y, inst.boundsMax.z) - o) / ro.w;
  rr.lo = max(ivec3(floor(bmin)), ivec3(0));
  rr.hi = min(ivec3(floor(bmax)), ivec3(7));
  rr.any = rr.lo.x <= rr.hi.x && rr.lo.y <= rr.hi.y && rr.lo.z <= rr.hi.z && bmax.x >= 0.0f &&
           bmax.y >= 0.0f && bmax.z >= 0.0f && bmin.x <= 8.0f && bmin.y <= 8.0f && bmin.z <= 8.0f;
  // Size rule: cascade c's voxel is ro.w / 16 stack voxels; an object whose bounding radius is
  // below sizeRule voxels of it is not listed there (cascade 0 lists every object).
  if (c > 0u && inst.boundsMax.w < OBJ_FRAME.params.x * ro.w / 16.0f) rr.any = false;
  return rr;
}

// The instance nearest to stack point p among those listed in the region that holds it (the
// finest of cascades >= firstCascade), as (distance, instance); distance 1e30 when none is
// listed; instances whose bounding radius is below minRadius are skipped. The distance is a lower
// bound (objInstanceDistance), negative inside: probes inside an object are turned off instead of
// going black, and probes near a large one relocate away from it.
vec2 objNearestListed(vec3 p, uint firstCascade, float minRadius) {
  vec2 best = vec2(1e30f, 0.0f);
  uint cascades = OBJ_FRAME.counts.y;
  if (OBJ_FRAME.counts.x == 0u) return best;
  for (uint c = firstCascade; c < cascades; ++c) {
    if (!objInRegionGrid(c, p)) continue;
    vec4 ro = OBJ_FRAME.regionOrigin[c];
    ivec3 r = clamp(ivec3(floor((p - vec3(ro.x, ro.y, ro.z)) / ro.w)), ivec3(0), ivec3(7));
    ObjectRegionGpu region = OBJ_REGION(c * 512u + uint(r.x) + 8u * (uint(r.y) + 8u * uint(r.z)));
    for (uint k = 0u; k < region.count; ++k) {
      uint i = OBJ_LIST(region.start + k).x;
      if (OBJ_INSTANCE(i).boundsMax.w < minRadius) continue;
      float d = objInstanceDistance(i, p);
      if (d < best.x) best = vec2(d, float(i));
    }
    return best;
  }
  return best;
}

// Whether stack point p lies in a sub-cell within wake distance of an instance that moved,
// appeared or vanished this frame (ObjectRegionGpu::wake, built by the host from each change's
// size: ObjectSceneSettings::wakeIrradianceChange), in cascade c's region grid or the coarsest
// one for coarser probes: the probe there must wake up (Majercik 2021 Sec. 5: probes near
// dynamic changes become vigilant). One bit read.
bool objMovedNear(vec3 p, uint c) {
  uint cascades = OBJ_FRAME.counts.y;  // removals leave wake bits but no instance
  if (cascades == 0u) return false;
  uint k = min(c, cascades - 1u);
  vec4 ro = OBJ_FRAME.regionOrigin[k];
  vec3 s = floor((p - vec3(ro.x, ro.y, ro.z)) * (float(kSubCellsPerAxis) / ro.w));
  if (s.x < 0.0f || s.y < 0.0f || s.z < 0.0f || s.x > 63.0f || s.y > 63.0f || s.z > 63.0f)
    return false;
  ivec3 q = ivec3(s);
  ivec3 r = q / 8;
  ivec3 sub = q - 8 * r;
  uint word = OBJ_REGION(k * 512u + uint(r.x) + 8u * (uint(r.y) + 8u * uint(r.z)))
                  .wake[objOccupancyWord(sub.y, sub.z)];
  return ((word >> (objOccupancyShift(sub.y) + uint(sub.x))) & 1u) != 0u;
}
