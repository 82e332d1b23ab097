#version 450
// Batched irradiance(x, n, view) queries of the probe field (probeFieldIrradiance): one
// invocation per query (position.w = 1 + cascade samples that cascade alone, 0 = all);
// results rgb = irradiance, a = 0. A query whose normal is zero has no surface: irradiance 0.
// At reduced resolution, one invocation per S×S block of an image of queries (S = dispatch.x, 2
// or 4; probe_upsample.glsl; probe_upsample.comp then fills in the other pixels).
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
#define PROBE_UPSAMPLE_QUERY(i) queries[i]
#include "shaders/probe_upsample.glsl"
// Half resolution and the near-field gather are pipelines of their own (ProbeField::sample_):
// as a uniform branch, the half mode's index arithmetic cost the list mode 3% on the H200
// (Chebyshev only, 0.477 -> 0.491 ms). Constant 0: bit 0 half resolution, bit 1 near field.
layout(constant_id = 0) const uint kSampleVariant = 0u;
const bool kHalfImage = (kSampleVariant & 1u) != 0u;
const bool kNearField = (kSampleVariant & 2u) != 0u;

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
  // A list: query id, result id. At reduced resolution (kHalfImage; dispatch.x = the block size
  // S, dispatch.zw = the full-resolution image's size, probe_upsample.glsl): the low-resolution
  // pixel of invocation id in tile order, its block's sampled pixel's query, a result per
  // low-resolution pixel.
  uint queryIndex = min(id, max(pc.dispatch.y, 1u) - 1u);
  uint resultIndex = id;
  uint halfPixel = 0u;  // the sampled pixel's index in its block (S²: none)
  if (kHalfImage) {
    uint size = pc.dispatch.x;
    uint width = pc.dispatch.z;
    uint height = pc.dispatch.w;
    uint lowWidth = (width + size - 1u) / size;
    uvec2 block = probeTiledPixel(id, lowWidth);
    bool inside = block.x < lowWidth && block.y < (height + size - 1u) / size;
    halfPixel = inside ? probeBlockSampledPixel(block, size, width, height) : size * size;
    uvec2 pixel = block * size + uvec2(halfPixel % size, halfPixel / size);
    queryIndex = halfPixel < size * size ? pixel.x + width * pixel.y : 0u;
    resultIndex = block.x + lowWidth * block.y;
    valid = valid && inside;
  }
  ProbeQuery q = queries[queryIndex];
  // No surface (a normal of zero): irradiance 0, and the lane takes no part in sharing.
  bool surface = valid && probeQueryHasSurface(q);
  // The near-field gather (shaders/probe_near_field.glsl): every query on its own; a constant,
  // so the whole workgroup leaves before the sharing's barriers.
  if (kNearField) {
    if (!valid) return;
    vec3 e = surface ? probeNearFieldIrradiance(frame, q.position.xyz, q.normal.xyz) : vec3(0.0);
    results[resultIndex] = vec4(e, kHalfImage ? (surface ? float(halfPixel) : -1.0) : 0.0);
    return;
  }
  ProbeFieldPlan plan;
  plan.count = 0u;
  if (surface)
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
  if (!surface) {
    results[resultIndex] = vec4(0.0, 0.0, 0.0, kHalfImage ? -1.0 : 0.0);
    return;
  }
  uint visible0 = sharedVisible[lane][0];
  uint visible1 = sharedVisible[lane][1];
  for (uint k = 0u; k < kProbeSampleShareLanes; ++k) {
    if ((sharesMask & 1u) != 0u) visible0 |= sharedVisible[lead + k][0];
    if ((sharesMask & 2u) != 0u) visible1 |= sharedVisible[lead + k][1];
  }
  results[resultIndex] = vec4(probeFieldFinish(frame, plan, q.position.xyz, q.normal.xyz,
                                               q.view.xyz, visible0, visible1),
                              kHalfImage ? float(halfPixel) : 0.0);
}
