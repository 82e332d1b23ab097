#version 450
// The scan of the region passes (object_regions.comp), between their rank pass and their sub-cell
// count: one workgroup turns every region's counts into starts, exclusive prefix sums in region
// order of the list entries, the occupied sub-cells (one sub-cell header each, counted by the
// rank pass) and the sub-cell entries, clamped to the capacities the host sized. 256 threads of
// 8 consecutive regions each (2,048 regions at most), three loads per region: the per-region
// work (ranks, occupied box) runs before, one thread per region. A single workgroup walking the
// occupancy words itself took 0.11 ms on an H100 (docs/DECISIONS.md, "Object lists per occupied
// sub-cell").
#extension GL_GOOGLE_include_directive : require

#define SDF_PRECISE precise
#define OBJ_BINDING_BASE 0
#include "shaders/object_bindings.glsl"

layout(push_constant) uniform Push { ObjectRegionPush pc; };

layout(local_size_x = kRegionScanThreads) in;

shared uvec3 sums[2][kRegionScanThreads];

void main() {
  uint total = pc.cascades * kRegionsPerCascade;
  uint chunk = (total + kRegionScanThreads - 1u) / kRegionScanThreads;
  uint lid = gl_LocalInvocationID.x;
  uint begin = min(lid * chunk, total);
  uint end = min(begin + chunk, total);
  // x: list entries, y: sub-cell headers (occupied sub-cells), z: sub-cell entries.
  uvec3 own = uvec3(0u);
  for (uint r = begin; r < end; ++r)
    own += uvec3(objRegions[r].count, objRegions[r].subBase, objRegions[r].subStart);
  // Inclusive Hillis-Steele scan of the threads' sums, then shifted to exclusive.
  uint from = 0u;
  sums[0][lid] = own;
  barrier();
  for (uint offset = 1u; offset < kRegionScanThreads; offset <<= 1u) {
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
    uint rank = objRegions[r].subBase;  // the region's occupied sub-cells (rank pass)
    uint entries = objRegions[r].subStart;
    // A capacity of 0: no sub-cell lists this frame (their passes are not recorded).
    bool fits = pc.subCapacity > 0u && at.y + rank <= pc.subCapacity &&
                at.z + entries <= pc.subCapacity;
    objRegions[r].subBase = fits ? pc.capacity + at.y : kNoSubLists;
    objRegions[r].subStart = pc.capacity + pc.subCapacity + min(at.z, pc.subCapacity);
    at += uvec3(n, rank, entries);
  }
}
