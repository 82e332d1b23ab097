#version 450
// Batched irradiance(x, n, view) queries of the probe field (probeFieldIrradiance): one
// invocation per query (position.w = 1 + cascade samples that cascade alone, 0 = all);
// results rgb = irradiance, a = 0.
//
// The SDF visibility tests dominate the pass (docs/GPU_BUDGET.md). Queries are expected in
// pixel tiles (ProbeField::sample), so kProbeSampleShareLanes consecutive ones (a group) are
// usually neighbouring pixels in the same probe cages: a group that shares a cage splits the
// union of its open tests among its lanes (probeGroupSharesCage). Each invocation plans, the
// workgroup exchanges plans through shared memory, traces, exchanges answers, and finishes. The
// CPU reference (ProbeFieldCpu::sample) groups queries the same way.
#extension GL_GOOGLE_include_directive : require
// The distance atlas only, as the engine's include (sdfstream/probe_sample.glsl) reads it: with
// both atlases' paths compiled in, this pass ran 1.88 -> 2.82 ms at 1080p on the H200 (Sponza;
// 0.48 -> 0.60 ms with Chebyshev alone, which traces nothing: the code, not the loads, cost it).
#define PROBE_DISTANCE_ATLAS_ONLY
#include "shaders/probe_bindings.glsl"

const uint kNoCage = 0xffffffffu;
shared uint sharedCascade[64][2];
shared ivec4 sharedBase[64][2];
shared vec4 sharedBiased[64][2];
shared uint sharedTraceMask[64][2];
shared uint sharedVisible[64][2];

ProbeCage groupCage(uint lane, uint i) {
  ProbeCage c;
  c.cascade = sharedCascade[lane][i];
  c.base = ivec3(sharedBase[lane][i]);
  c.biased = vec3(sharedBiased[lane][i]);
  return c;
}

void main() {
  uint id = probeInvocation();
  uint lane = gl_LocalInvocationIndex;
  uint lead = lane & ~(kProbeSampleShareLanes - 1u);
  bool valid = id < pc.dispatch.y;
  ProbeQuery q = queries[min(id, max(pc.dispatch.y, 1u) - 1u)];
  ProbeFieldPlan plan;
  plan.count = 0u;
  if (valid)
    plan = probeFieldPlan(frame, q.position.xyz, q.normal.xyz, q.view.xyz, int(q.position.w) - 1);
  // Cages by constant indices or probePlanCage only: a variable index keeps the plan in local
  // memory (probe_sample.glsl, probeFieldPlan).
  for (uint i = 0u; i < 2u; ++i) {
    bool has = i < plan.count;
    ProbeCage cage = probePlanCage(plan, i);
    sharedCascade[lane][i] = has ? cage.cascade : kNoCage;
    sharedBase[lane][i] = has ? ivec4(cage.base, 0) : ivec4(0);
    sharedBiased[lane][i] = has ? vec4(cage.biased, 0.0) : vec4(0.0);
    sharedTraceMask[lane][i] = has ? cage.traceMask : 0u;
  }
  barrier();
  uint sharesMask = 0u;  // bit i: cage i's tests are shared by the group
  bool perQuery = (frame.options.x & kProbeOptionSdfPerQuery) != 0u;
  for (uint i = 0u; i < 2u; ++i) {
    bool shares = !perQuery && sharedCascade[lead][i] != kNoCage;
    for (uint k = 1u; k < kProbeSampleShareLanes; ++k)
      shares = shares && sharedCascade[lead + k][i] != kNoCage &&
               probeGroupSharesCage(groupCage(lead, i), groupCage(lead + k, i));
    if (shares) sharesMask |= 1u << i;
    uint visible = 0u;
    if (i < plan.count) {
      ProbeCage cage = probePlanCage(plan, i);
      uint corners = cage.traceMask;
      if (shares) {
        uint all = 0u;
        for (uint k = 0u; k < kProbeSampleShareLanes; ++k) all |= sharedTraceMask[lead + k][i];
        corners = probeGroupLaneCorners(all, lane - lead);
      }
      // A shared cage is the same cage in every lane: only the set of corners differs.
      visible = probeCageTrace(frame, cage, corners, cage.biased);
    }
    sharedVisible[lane][i] = visible;
  }
  barrier();
  if (!valid) return;
  uint visible0 = sharedVisible[lane][0];
  uint visible1 = sharedVisible[lane][1];
  for (uint k = 0u; k < kProbeSampleShareLanes; ++k) {
    if ((sharesMask & 1u) != 0u) visible0 |= sharedVisible[lead + k][0];
    if ((sharesMask & 2u) != 0u) visible1 |= sharedVisible[lead + k][1];
  }
  results[id] = vec4(probeFieldFinish(frame, plan, q.position.xyz, q.normal.xyz, q.view.xyz,
                                      visible0, visible1),
                     0.0);
}
