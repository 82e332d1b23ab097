#version 450
// The scan between the region passes' count and their sub-cell count (object_regions.comp):
// one workgroup turns every region's counts into starts, exclusive prefix sums in region order
// of the list entries, the occupied sub-cells (one sub-cell header each) and the sub-cell
// entries, clamped to the capacities the host sized; it also writes each region's occupancy
// ranks and the box of its occupied sub-cells (object_layout.h). 256 threads of 8 consecutive regions each (2,048 regions at most):
// with 64 threads of 32 regions the dependent loads of a thread's chunk made this one pass
// 0.11 ms on an H100 (docs/DECISIONS.md, "Object lists per occupied sub-cell").
#extension GL_GOOGLE_include_directive : require

#define SDF_PRECISE precise
#define OBJ_BINDING_BASE 0
#include "shaders/object_bindings.glsl"

layout(push_constant) uniform Push { ObjectRegionPush pc; };

#include "shaders/object_trace.glsl"

const uint kScanThreads = 256u;
layout(local_size_x = 256) in;

shared uvec3 sums[2][kScanThreads];

uint occupiedSubCells(uint r) {
  uint n = 0u;
  for (uint w = 0u; w < kOccupancyWords; ++w) n += uint(bitCount(objRegions[r].occupancy[w]));
  return n;
}

void main() {
  uint total = pc.cascades * kRegionsPerCascade;
  uint chunk = (total + kScanThreads - 1u) / kScanThreads;
  uint lid = gl_LocalInvocationID.x;
  uint begin = min(lid * chunk, total);
  uint end = min(begin + chunk, total);
  // x: list entries, y: sub-cell headers (occupied sub-cells), z: sub-cell entries.
  uvec3 own = uvec3(0u);
  for (uint r = begin; r < end; ++r)
    own += uvec3(objRegions[r].count, occupiedSubCells(r), objRegions[r].subStart);
  // Inclusive Hillis-Steele scan of the threads' sums, then shifted to exclusive.
  uint from = 0u;
  sums[0][lid] = own;
  barrier();
  for (uint offset = 1u; offset < kScanThreads; offset <<= 1u) {
    uvec3 v = sums[from][lid];
    if (lid >= offset) v += sums[from][lid - offset];
    sums[1u - from][lid] = v;
    from = 1u - from;
    barrier();
  }
  uvec3 at = sums[from][lid] - own;
  for (uint r = begin; r < end; ++r) {
    uint n = objRegions[r].count;
    uint s = min(at.x, pc.capacity);
    objRegions[r].start = s;
    objRegions[r].count = min(n, pc.capacity - s);  // never past the list (host sizes it so)
    objRegions[r].wide = min(objRegions[r].wide, objRegions[r].count);
    objRegions[r].cursor = 0u;
    objRegions[r].wideCursor = 0u;
    uint rank = 0u;
    for (uint w = 0u; w < kOccupancyWords; w += 2u) {
      uint next = rank + uint(bitCount(objRegions[r].occupancy[w]));
      objRegions[r].rank[w / 2u] = rank | (next << 16u);
      rank = next + uint(bitCount(objRegions[r].occupancy[w + 1u]));
    }
    objRegions[r].occupiedBounds = objOccupiedBounds(objRegions[r].occupancy);
    uint entries = objRegions[r].subStart;
    bool fits = at.y + rank <= pc.subCapacity && at.z + entries <= pc.subCapacity;
    objRegions[r].subBase = fits ? pc.capacity + at.y : kNoSubLists;
    objRegions[r].subStart = pc.capacity + pc.subCapacity + min(at.z, pc.subCapacity);
    at += uvec3(n, rank, entries);
  }
}
