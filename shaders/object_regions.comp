#version 450
// Macro-region object lists, rebuilt every frame from the instances (gi/object_scene.h; Godot
// SDFGI slides b, "Storing the object list per region": a compute pass per object over the
// regions it may touch, culling each region against the object's oriented box, atomics to mark
// presence). Compact lists instead of the slides' bitfields, so a ray pays for the objects in a
// region, not for N/32 words of it (docs/DECISIONS.md). Three phases, one dispatch each:
//   0 count: workgroup (instance, cascade); its 64 threads stride over the regions of the
//            instance's AABB range and atomically count those its OBB overlaps and OR the
//            sub-cells its AABB touches into the region's occupancy bitfield (the wake bits,
//            which need the instances' old poses too, come from the host);
//   1 scan:  one workgroup turns counts into list starts (exclusive prefix sum), clamped to the
//            list capacity the host sized from the same AABB ranges;
//   2 fill:  as 0, appending the instance's entry (index and quantised AABB, objListEntry) at
//            start + atomicAdd(cursor).
// Cost: instances × regions of their AABBs, plus one scan of cascades × 512 counts.
#extension GL_GOOGLE_include_directive : require

#define SDF_PRECISE precise
#define OBJ_BINDING_BASE 0
#include "shaders/object_bindings.glsl"

layout(push_constant) uniform Push { ObjectRegionPush pc; };

#include "shaders/object_trace.glsl"

layout(local_size_x = 64) in;

shared uint partial[64];

void scanRegions() {
  uint total = pc.cascades * kRegionsPerCascade;
  uint chunk = (total + 63u) / 64u;
  uint lid = gl_LocalInvocationID.x;
  uint begin = min(lid * chunk, total);
  uint end = min(begin + chunk, total);
  uint sum = 0u;
  for (uint r = begin; r < end; ++r) sum += objRegions[r].count;
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
  uint start = partial[lid];
  for (uint r = begin; r < end; ++r) {
    uint n = objRegions[r].count;
    uint s = min(start, pc.capacity);
    objRegions[r].start = s;
    objRegions[r].count = min(n, pc.capacity - s);  // never past the list (host sizes it so)
    objRegions[r].cursor = 0u;
    start += n;
  }
}

void main() {
  if (pc.phase == 1u) {
    scanRegions();
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
  ivec3 ext = rr.hi - rr.lo + ivec3(1);
  uint n = uint(ext.x * ext.y * ext.z);
  vec4 ro = objFrame.regionOrigin[c];
  for (uint k = gl_LocalInvocationID.x; k < n; k += 64u) {
    ivec3 r = rr.lo + ivec3(int(k % uint(ext.x)), int((k / uint(ext.x)) % uint(ext.y)),
                            int(k / uint(ext.x * ext.y)));
    vec3 lo = vec3(ro.x, ro.y, ro.z) + vec3(r) * ro.w;
    if (!objObbOverlapsBox(inst, dims, lo, lo + vec3(ro.w))) continue;
    uint region = c * kRegionsPerCascade + uint(r.x + 8 * (r.y + 8 * r.z));
    if (pc.phase == 0u) {
      atomicAdd(objRegions[region].count, 1u);
      ObjSubRange sr =
          objSubCellRange(vec3(inst.boundsMin.x, inst.boundsMin.y, inst.boundsMin.z),
                          vec3(inst.boundsMax.x, inst.boundsMax.y, inst.boundsMax.z), lo, ro.w);
      uint row = objRowMask(sr.lo.x, sr.hi.x);
      for (int z = sr.lo.z; z <= sr.hi.z; ++z)
        for (int y = sr.lo.y; y <= sr.hi.y; ++y)
          atomicOr(objRegions[region].occupancy[objOccupancyWord(y, z)],
                   row << objOccupancyShift(y));
    } else {
      uint slot = atomicAdd(objRegions[region].cursor, 1u);
      if (slot < objRegions[region].count)
        objList[objRegions[region].start + slot] = objListEntry(
            i, vec3(inst.boundsMin.x, inst.boundsMin.y, inst.boundsMin.z),
            vec3(inst.boundsMax.x, inst.boundsMax.y, inst.boundsMax.z), lo, ro.w);
    }
  }
}
