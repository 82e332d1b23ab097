// The bindings every probe field pass shares (push descriptors: one buffer list for all of
// them, gi/probe_field.cpp), then shaders/probe_field_storage.glsl: the storage macros the probe
// field math expects (shaders/probe_field.glsl and its pass files) and that math, included in
// dependency order. GLSL only; the C++ reference is gi/probe_field_cpu.cpp.
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/probe_layout.h"
#include "shaders/shared/light_layout.h"
#include "shaders/shared/color_codec.h"

layout(std430, binding = 0) readonly buffer Frame { ProbeFrame frame; };
layout(std430, binding = 1) readonly buffer Volumes { ProbeVolume volumes[]; };
layout(std430, binding = 2) buffer ProbeDataBuffer { vec4 probeData[]; };
layout(std430, binding = 3) buffer History { uvec4 history[]; };
layout(std430, binding = 4) buffer Irradiance { vec4 irradiance[]; };
layout(std430, binding = 5) buffer Depth { vec2 depth[]; };
layout(std430, binding = 6) buffer Rays { vec4 rays[]; };
layout(std430, binding = 7) buffer HitCache { uvec2 hitCache[]; };
layout(std430, binding = 8) readonly buffer RayPattern { vec4 rayPattern[]; };
layout(std430, binding = 9) buffer UpdateList { uint updateList[]; };
layout(std430, binding = 10) buffer Stats { uint stats[]; };
layout(std430, binding = 11) readonly buffer PageChanged { uint pageChanged[]; };
layout(std430, binding = 12) readonly buffer PageTable { uint pageTable[]; };
// The distance atlas or, where specialization constant 0 says so (sdf_trace.glsl), the same
// distances by cell (sdf_layout.h kBrickCornerWords: a trace's sample is one load). A pass that
// defines PROBE_DISTANCE_ATLAS_ONLY is always given the distance atlas (ProbeField::bindings).
layout(std430, binding = 13) readonly buffer DistanceAtlas { uint distanceAtlas[]; };
#ifndef PROBE_DISTANCE_ATLAS_ONLY
layout(std430, binding = 13) readonly buffer CornerAtlas { uvec4 cornerAtlas[]; };
#define SDF_CELL_CORNERS(i) cornerAtlas[i]
#endif
layout(std430, binding = 14) readonly buffer AlbedoAtlas { uint albedoAtlas[]; };
layout(std430, binding = 15) readonly buffer EmissionAtlas { uint emissionAtlas[]; };
layout(std430, binding = 16) readonly buffer Cascades { CascadeTraceParams cascades[]; };
layout(std430, binding = 17) readonly buffer LightRadiance { uint lightRadiance[]; };
layout(std430, binding = 18) readonly buffer Queries { ProbeQuery queries[]; };
layout(std430, binding = 19) writeonly buffer Results { vec4 results[]; };
layout(std430, binding = 20) buffer DispatchArgs { uint dispatchArgs[]; };
layout(std430, binding = 21) buffer RayDirs { vec4 rayDirs[]; };
layout(std430, binding = 30) buffer BounceCells { uint bounceCells[]; };
layout(std430, binding = 31) buffer BounceWork { uvec4 bounceWork[]; };

// Moving objects (gi/object_scene.h): bindings 22-29; a frame without objects binds the probe
// field's placeholders and leaves kProbeOptionObjects clear. 30-31 (above) are the bounce cells
// and their passes' work: 32 in all, the least maxPushDescriptors Vulkan allows.
#define OBJ_BINDING_BASE 22
#include "shaders/object_bindings.glsl"

layout(push_constant) uniform Push { ProbePushConstants pc; };

// Per-ray counters of the trace pass (rays cached/traced, steps, object rays): one atomic per
// subgroup instead of one per invocation. Every ray of a frame adds to the same few words (2.5 M
// same-address atomics a frame at the default); the H200's driver turned out to aggregate them
// already (trace pass 0.80 ms either way, docs/GPU_BUDGET.md), so this only stops the cost from
// depending on that. Subgroup operations act on the active invocations, so calls inside
// divergent branches stay correct. The CPU reference adds one at a time (same totals).
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
void probeStatCount(uint i, uint v) {
  uint total = subgroupAdd(v);
  if (subgroupElect()) atomicAdd(stats[i], total);
}
#define PROBE_STAT_COUNT(i, v) probeStatCount(i, v)

// A slot of list i (its length a stats word) for each invocation that calls this: one atomic
// per subgroup. The first active invocation is both the one elected and the one broadcast from.
#extension GL_KHR_shader_subgroup_ballot : require
uint probeAppend(uint i) {
  uvec4 ballot = subgroupBallot(true);
  uint base = 0u;
  if (subgroupElect()) base = atomicAdd(stats[i], subgroupBallotBitCount(ballot));
  return subgroupBroadcastFirst(base) + subgroupBallotExclusiveBitCount(ballot);
}
#define PROBE_APPEND(i) probeAppend(i)

#include "shaders/probe_field_storage.glsl"

layout(local_size_x = 64) in;

// Linear invocation index: large dispatches are spread over y (64 x 16384 threads per row).
uint probeInvocation() {
  return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
}

// Threads of this dispatch that have work: list-driven passes stop at the list's length.
uint probeListLength() {
  return min(stats[kProbeStatListCount], frame.selection.y);
}
