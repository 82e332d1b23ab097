#version 450
// Macro-region object lists and their sub-cell lists, rebuilt every frame from the instances
// (gi/object_scene.h; Godot SDFGI slides b, "Storing the object list per region": a compute pass
// per object over the regions it may touch, culling each region against the object's oriented
// box, atomics to mark presence). Compact lists instead of the slides' bitfields, so a ray pays
// for the objects in a region, not for N/32 words of it (docs/DECISIONS.md); and per occupied
// sub-cell a list of the instances whose AABB touches it (object_layout.h), so a ray pays only
// for the objects of the sub-cells it crosses. Six phases, one dispatch each; the host zeroes
// the sub-cell headers before the first:
//   0 count:     workgroup (instance, cascade); its 64 threads stride over the regions of the
//                instance's AABB range and atomically count those its OBB overlaps; for a wide
//                instance (more than kSubListMaxCells sub-cells) the wide count, else the
//                sub-cells it touches into the occupancy bitfield and its sub-cell entries (the
//                wake bits, which need the instances' old poses too, come from the host);
//   1 rank:      thread per region: the occupancy words' ranks, the occupied sub-cells' box and
//                their count;
//   2 scan:      object_regions_scan.comp, one workgroup: the counts into list starts
//                (exclusive prefix sums of the entries, the occupied sub-cells and the sub-cell
//                entries), clamped to the capacities the host sized from the same AABB ranges;
//   3 sub-count: as 0, counting each non-wide instance into the headers of its sub-cells;
//   4 sub-scan:  workgroup per region: its headers' counts into entry starts;
//   5 fill:      as 0, appending the instance's entry (index and quantised AABB, objListEntry)
//                to its region's list (wide ones first) and to its sub-cells' lists.
// A frame without sub-cell lists (short region lists, ObjectSceneSettings::subListMinMeanEntries)
// runs phase 6 alone: the host has sized each region's slots from the same AABB ranges and
// written its start, so an instance appends its entry with one atomic on the region's count and
// ORs its sub-cells into the occupancy and their masks into occupiedBounds. No entry comes first
// (wide stays 0): the walk tests them all from the first occupied sub-cell a ray crosses.
// Cost: instances × regions of their AABBs × (1 + sub-cells touched), plus the two scans.
#extension GL_GOOGLE_include_directive : require

#define SDF_PRECISE precise
#define OBJ_BINDING_BASE 0
#include "shaders/object_bindings.glsl"

layout(push_constant) uniform Push { ObjectRegionPush pc; };

#include "shaders/object_trace.glsl"

layout(local_size_x = 64) in;

shared uint partial[64];

uint occupiedSubCells(uint r) {
  return (objRegions[r].rank[kOccupancyWords / 2u - 1u] >> 16u) +
         uint(bitCount(objRegions[r].occupancy[kOccupancyWords - 1u]));
}

// Phase 4, one workgroup per region: the region's headers (in rank order) get their entries'
// starts, one run after the other from the region's subStart.
void scanSubCells() {
  uint r = gl_WorkGroupID.x;
  uint lid = gl_LocalInvocationID.x;
  if (r >= pc.cascades * kRegionsPerCascade) return;
  uint base = objRegions[r].subBase;
  if (base == kNoSubLists || objRegions[r].count == objRegions[r].wide) return;
  uint n = occupiedSubCells(r);
  uint begin = min(lid * 8u, n);
  uint end = min(begin + 8u, n);
  uint sum = 0u;
  for (uint h = begin; h < end; ++h) sum += objList[base + h].y;
  partial[lid] = sum;
  barrier();
  if (lid == 0u) {
    uint run = 0u;
    for (uint k = 0u; k < 64u; ++k) {
      uint v = partial[k];
      partial[k] = run;
      run += v;
    }
  }
  barrier();
  uint at = objRegions[r].subStart + partial[lid];
  for (uint h = begin; h < end; ++h) {
    objList[base + h].x = at;
    objList[base + h].z = 0u;
    at += objList[base + h].y;
  }
}

// Phase 1, one thread per region: the occupancy words' ranks, the box of the occupied
// sub-cells, and their count (left in subBase for the scan). Spread over the GPU: the scan's
// single workgroup would issue these scattered accesses from one SM.
void rankRegion() {
  uint r = gl_GlobalInvocationID.x;
  if (r >= pc.cascades * kRegionsPerCascade) return;
  uint occupancy[kOccupancyWords] = objRegions[r].occupancy;
  uint before = 0u;
  for (uint w = 0u; w < kOccupancyWords; w += 2u) {
    uint first = uint(bitCount(occupancy[w]));
    objRegions[r].rank[w / 2u] = before | ((before + first) << 16u);
    before += first + uint(bitCount(occupancy[w + 1u]));
  }
  objRegions[r].occupiedBounds = objOccupiedBounds(occupancy);
  objRegions[r].subBase = before;
}

void main() {
  if (pc.phase == 1u) {
    rankRegion();
    return;
  }
  if (pc.phase == 4u) {
    scanSubCells();
    return;
  }
  uint i = gl_WorkGroupID.x;
  uint c = gl_WorkGroupID.y;
  if (i >= pc.instances || c >= pc.cascades) return;
  ObjectInstanceGpu inst = objInstances[i];
  ObjRegionRange rr = objRegionRange(inst, c);
  if (!rr.any) return;
  ObjectMeshGpu m = objMeshes[inst.info.x];
  uvec3 dims = uvec3(m.dimsOffset.x, m.dimsOffset.y, m.dimsOffset.z);
  vec3 bmin = vec3(inst.boundsMin.x, inst.boundsMin.y, inst.boundsMin.z);
  vec3 bmax = vec3(inst.boundsMax.x, inst.boundsMax.y, inst.boundsMax.z);
  ivec3 ext = rr.hi - rr.lo + ivec3(1);
  uint n = uint(ext.x * ext.y * ext.z);
  vec4 ro = objFrame.regionOrigin[c];
  for (uint k = gl_LocalInvocationID.x; k < n; k += 64u) {
    ivec3 r = rr.lo + ivec3(int(k % uint(ext.x)), int((k / uint(ext.x)) % uint(ext.y)),
                            int(k / uint(ext.x * ext.y)));
    vec3 lo = vec3(ro.x, ro.y, ro.z) + vec3(r) * ro.w;
    if (!objObbOverlapsBox(inst, dims, lo, lo + vec3(ro.w))) continue;
    uint region = c * kRegionsPerCascade + uint(r.x + 8 * (r.y + 8 * r.z));
    ObjSubRange sr = objSubCellRange(bmin, bmax, lo, ro.w);
    uint cells = objSubCellCount(sr);
    bool wide = cells > kSubListMaxCells;
    if (pc.phase == 0u) {
      atomicAdd(objRegions[region].count, 1u);
      if (wide) {
        atomicAdd(objRegions[region].wide, 1u);
        continue;
      }
      atomicAdd(objRegions[region].subStart, cells);
      uint row = objRowMask(sr.lo.x, sr.hi.x);
      for (int z = sr.lo.z; z <= sr.hi.z; ++z)
        for (int y = sr.lo.y; y <= sr.hi.y; ++y)
          atomicOr(objRegions[region].occupancy[objOccupancyWord(y, z)],
                   row << objOccupancyShift(y));
      continue;
    }
    uvec4 entry = objListEntry(i, bmin, bmax, lo, ro.w);
    if (pc.phase == 6u) {
      uint at = atomicAdd(objRegions[region].count, 1u);
      if (at < objRegions[region].slots) {
        objList[objRegions[region].start + at] = entry;
      } else {  // past the host's slots (its ranges are the same math): dropped, not counted
        atomicAdd(objRegions[region].count, 0xffffffffu);
        continue;
      }
      // Every instance's sub-cells, wide ones too (no entry comes first in these lists), and
      // their masks for the walk's box of occupied sub-cells.
      atomicOr(objRegions[region].occupiedBounds, objSubRangeMasks(sr));
      uint row = objRowMask(sr.lo.x, sr.hi.x);
      for (int z = sr.lo.z; z <= sr.hi.z; ++z)
        for (int y = sr.lo.y; y <= sr.hi.y; ++y)
          atomicOr(objRegions[region].occupancy[objOccupancyWord(y, z)],
                   row << objOccupancyShift(y));
      continue;
    }
    if (pc.phase == 5u) {
      uint wideCount = objRegions[region].wide;
      uint at = wide ? atomicAdd(objRegions[region].wideCursor, 1u)
                     : wideCount + atomicAdd(objRegions[region].cursor, 1u);
      if (at < objRegions[region].count) objList[objRegions[region].start + at] = entry;
    }
    uint base = objRegions[region].subBase;
    if (wide || base == kNoSubLists) continue;
    for (int z = sr.lo.z; z <= sr.hi.z; ++z)
      for (int y = sr.lo.y; y <= sr.hi.y; ++y)
        for (int x = sr.lo.x; x <= sr.hi.x; ++x) {
          uint h = base + objSubRank(region, uint(x + 8 * y + 64 * z));
          if (pc.phase == 3u) {
            atomicAdd(objList[h].y, 1u);
          } else {
            uint slot = atomicAdd(objList[h].z, 1u);
            if (slot < objList[h].y) objList[objList[h].x + slot] = entry;
          }
        }
  }
}
