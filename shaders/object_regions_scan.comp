#version 450
// The scan of the region passes (object_regions.comp), between their rank pass and their sub-cell
// count: one workgroup turns every region's counts into starts, exclusive prefix sums in region
// order of the list entries, the occupied sub-cells (one sub-cell header each, counted by the
// rank pass) and the sub-cell entries, clamped to the capacities the host sized. 512 threads of
// 4 consecutive regions each (2,048 regions at most). Only frames with sub-cell lists run it:
// short lists are placed by the host (object_regions.comp, phase 6).
// One SM issues every access, and a warp's access to a field of 32 regions 208 bytes apart is 32
// transactions: field by field, read, reread and written, that was ~27,000 of them, 0.043 ms on
// an H100 with the rank pass before it, whatever the object count. So each region's first 32
// bytes (count .. wideCursor) are read once and written once as two 16-byte words through a
// second view of the buffer (the struct's 4-byte alignment keeps the compiler from merging its
// fields), and the counts stay in registers across the scan: 4 transactions a region. The
// per-region rank work runs before, spread over the GPU (docs/DECISIONS.md, "The region scan:
// two 16-byte words a region").
#extension GL_GOOGLE_include_directive : require

#define SDF_PRECISE precise
#define OBJ_BINDING_BASE 0
#include "shaders/object_bindings.glsl"

// The regions again, as 16-byte words (kRegionVec4s a region; the header is words 0 and 1).
layout(std430, binding = OBJ_BINDING_BASE + 2) buffer ObjectRegionWords { uvec4 objRegionWords[]; };

layout(push_constant) uniform Push { ObjectRegionPush pc; };

layout(local_size_x = kRegionScanThreads) in;

const uint kScanRegionsPerThread = kMaxRegionCascades * kRegionsPerCascade / kRegionScanThreads;

shared uvec3 sums[2][kRegionScanThreads];

void main() {
  uint total = pc.cascades * kRegionsPerCascade;
  uint lid = gl_LocalInvocationID.x;
  // Header words: a = (count, start, wide, subBase = occupied sub-cells), b = (occupiedBounds,
  // subStart = sub-cell entries, cursor, wideCursor).
  uvec4 a[kScanRegionsPerThread];
  uvec4 b[kScanRegionsPerThread];
  uvec3 own = uvec3(0u);  // x: list entries, y: sub-cell headers, z: sub-cell entries
  for (uint j = 0u; j < kScanRegionsPerThread; ++j) {
    uint r = lid * kScanRegionsPerThread + j;
    a[j] = uvec4(0u);
    b[j] = uvec4(0u);
    if (r >= total) continue;
    a[j] = objRegionWords[r * kRegionVec4s];
    b[j] = objRegionWords[r * kRegionVec4s + 1u];
    own += uvec3(a[j].x, a[j].w, b[j].y);
  }
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
  for (uint j = 0u; j < kScanRegionsPerThread; ++j) {
    uint r = lid * kScanRegionsPerThread + j;
    if (r >= total) break;
    uint n = a[j].x;
    uint headers = a[j].w;
    uint entries = b[j].y;
    uint s = min(at.x, pc.capacity);
    uint listed = min(n, pc.capacity - s);  // never past the list (host sizes it so)
    // A region whose sub-cell headers or entries would pass the capacity is walked without them.
    bool fits = pc.subCapacity > 0u && at.y + headers <= pc.subCapacity &&
                at.z + entries <= pc.subCapacity;
    objRegionWords[r * kRegionVec4s] =
        uvec4(listed, s, min(a[j].z, listed), fits ? pc.capacity + at.y : kNoSubLists);
    objRegionWords[r * kRegionVec4s + 1u] =
        uvec4(b[j].x, pc.capacity + pc.subCapacity + min(at.z, pc.subCapacity), 0u, 0u);
    at += uvec3(n, headers, entries);
  }
}
