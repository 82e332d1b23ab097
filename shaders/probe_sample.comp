#version 450
// Batched irradiance(x, n, view) queries of the probe field (probeFieldIrradiance): one
// invocation per query (position.w = 1 + cascade samples that cascade alone, 0 = all);
// results rgb = irradiance, a = 0.
//
// The SDF visibility tests dominate the pass (docs/GPU_BUDGET.md). Queries come in pixel order,
// so kProbeSampleShareLanes consecutive ones (a group) are usually neighbouring pixels in the same
// probe cages: a group that shares a cage splits the union of its open tests among its lanes
// (probeGroupSharesCage). Each invocation plans, the workgroup exchanges plans through shared
// memory, traces, exchanges answers, and finishes. The CPU reference (ProbeFieldCpu::sample)
// groups queries the same way.
#extension GL_GOOGLE_include_directive : require
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
  for (uint i = 0u; i < 2u; ++i) {
    bool has = i < plan.count;
    sharedCascade[lane][i] = has ? plan.cage[i].cascade : kNoCage;
    sharedBase[lane][i] = has ? ivec4(plan.cage[i].base, 0) : ivec4(0);
    sharedBiased[lane][i] = has ? vec4(plan.cage[i].biased, 0.0) : vec4(0.0);
    sharedTraceMask[lane][i] = has ? plan.cage[i].traceMask : 0u;
  }
  barrier();
  bool shares[2];
  bool perQuery = (frame.options.x & kProbeOptionSdfPerQuery) != 0u;
  for (uint i = 0u; i < 2u; ++i) {
    shares[i] = !perQuery && sharedCascade[lead][i] != kNoCage;
    for (uint k = 1u; k < kProbeSampleShareLanes; ++k)
      shares[i] = shares[i] && sharedCascade[lead + k][i] != kNoCage &&
                  probeGroupSharesCage(groupCage(lead, i), groupCage(lead + k, i));
    uint visible = 0u;
    if (i < plan.count) {
      uint corners = plan.cage[i].traceMask;
      if (shares[i]) {
        uint all = 0u;
        for (uint k = 0u; k < kProbeSampleShareLanes; ++k) all |= sharedTraceMask[lead + k][i];
        corners = probeGroupLaneCorners(all, lane - lead);
      }
      // A shared cage is the same cage in every lane: only the set of corners differs.
      visible = probeCageTrace(frame, plan.cage[i], corners, plan.cage[i].biased);
    }
    sharedVisible[lane][i] = visible;
  }
  barrier();
  if (!valid) return;
  uint visible[2];
  for (uint i = 0u; i < 2u; ++i) {
    visible[i] = sharedVisible[lane][i];
    if (shares[i])
      for (uint k = 0u; k < kProbeSampleShareLanes; ++k) visible[i] |= sharedVisible[lead + k][i];
  }
  results[id] = vec4(probeFieldFinish(frame, plan, q.position.xyz, q.normal.xyz, q.view.xyz,
                                      visible[0], visible[1]),
                     0.0);
}
