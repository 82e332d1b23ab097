// The probe field's irradiance(x, n, view) (shaders/probe_field.glsl lists the pass files): the
// queries of probe_sample.comp, the multi-bounce term of probe_trace.glsl and engines' own
// shaders (shaders/include/sdfstream/probe_sample.glsl, installed). Reads only
//   PROBE_VOLUME(c)  -> ProbeVolume of cascade c
//   PROBE_DATA(g)    -> vec4 of global probe g (offset, state)
//   PROBE_IRRADIANCE(i), PROBE_DEPTH(i) through shaders/probe_update.glsl
//   SDF_CASCADE(c), SDF_PAGE(i), SDF_DIST_WORD(i) through sdfTraceStackFrom (SDF visibility)
// after shaders/probe_field.glsl, shaders/sdf_trace.glsl (SDF_CASCADE defined) and
// shaders/probe_update.glsl (PROBE_DEPTH defined).

// ---- Sampling: irradiance(x, n, view) ----------------------------------------------------------

// SDFDDGI's visibility (Sec. 4.2): the SDF is traced from the probe towards the receiver; a
// surface in between makes the probe invisible (a tiny weight, crushed to nothing below). Only hit
// or miss matters, so the trace steps by sdfVisibilitySteps, not exactly (shaders/sdf_trace.glsl).
// On top of Chebyshev by default: coarse cascades' depth texels mix misses and near hits (large
// variance), where Chebyshev alone lets light through one-voxel walls.
float probeSdfVisibility(ProbeFrame f, uint c, vec3 probe, vec3 receiver) {
  vec3 d = receiver - probe;
  float r = length(d);
  if (r < 1e-4f) return 1.0f;
  SdfStackResult s =
      sdfTraceStackWith(probe, d / r, 0.0f, r, 64u, sdfVisibilitySteps(f.trace.x), c, f.counts.x,
                        false);
  return s.r.hit ? 1e-4f : 1.0f;
}

// The SDF test's answer where the depth moments already give it (GI "Visibility" in
// docs/DECISIONS.md), else -1 (trace). The test exists for the corners Chebyshev would let
// through a thin wall: depth texels that mix near hits and far ones (large variance). Where the
// bilinearly filtered moments are decisive the trace is skipped and its likely answer used: a
// probe Chebyshev all but hides (weight below 0.1, which the crush below kProbeCrushThreshold
// then all but zeroes anyway; at a 0.05 crush a 0.05 threshold here read the same in the
// Breakfast Room, quick mode: relMSE 0.0731 against 0.0730) is blocked (1e-4, as a hit), and a
// receiver nearer than the mean depth of a narrow distribution (sigma <= 10% of the mean: every
// ray near that direction went at least about as far, so no wall stands in between) is visible.
// Without Chebyshev, or with kProbeOptionSdfEverywhere, every corner is traced.
float probeSdfVisibilityPresumed(ProbeFrame f, vec2 moments, float r, float chebyshev) {
  if ((f.options.x & (kProbeOptionSdfEverywhere | kProbeOptionNoChebyshev)) != 0u) return -1.0f;
  if (chebyshev < 0.1f) return 1e-4f;
  float variance = max(moments.y - moments.x * moments.x, 0.0f);
  return r <= moments.x && variance <= 0.01f * moments.x * moments.x ? 1.0f : -1.0f;
}

// One volume's cage around a receiver, everything but the open SDF tests: per corner the weight
// so far (backface x Chebyshev x the SDF answer where probeSdfVisibilityPresumed gives it), which
// corners are usable (on and updated) and which still need an SDF trace. Tracing is left to the
// caller, so that probe_sample.comp can share the traces of neighbouring receivers that sit in the
// same cage (probeGroupSharesCage); probeVolumeIrradiance traces them itself.
struct ProbeCage {
  uint cascade;
  ivec3 base;         // logical coordinate of corner 0
  vec3 alpha;         // trilinear position inside the cage
  vec3 biased;        // the receiver after the self-shadow bias (the SDF tests' target)
  float weight[8];
  uint usable;        // bit per corner
  uint traceMask;     // bit per corner whose SDF test is open
};

// Global probe g's position (relocated), cascade-0 voxels.
vec3 probePosition(ProbeFrame f, uint g) {
  ProbeVolume v = PROBE_VOLUME(g / f.counts.y);
  return probeGridPosition(v, probeLogicalCoord(v, g % f.counts.y)) + vec3(PROBE_DATA(g));
}

// Logical coordinate of a cage corner (clamped to the grid).
ivec3 probeCageCorner(ProbeVolume v, ProbeCage cage, uint corner) {
  ivec3 lc = cage.base + ivec3(int(corner & 1u), int((corner >> 1u) & 1u), int((corner >> 2u) & 1u));
  return min(lc, ivec3(int(v.countsRays.x) - 1, int(v.countsRays.y) - 1, int(v.countsRays.z) - 1));
}

// Global index of a cage corner's probe.
uint probeCageProbe(ProbeFrame f, ProbeCage cage, uint corner) {
  ProbeVolume v = PROBE_VOLUME(cage.cascade);
  return cage.cascade * f.counts.y + probeStorageIndex(v, probeCageCorner(v, cage, corner));
}

// A cage corner's probe position (relocated), cascade-0 voxels.
vec3 probeCageProbePosition(ProbeFrame f, ProbeCage cage, uint corner) {
  ProbeVolume v = PROBE_VOLUME(cage.cascade);
  return probeGridPosition(v, probeCageCorner(v, cage, corner)) +
         vec3(PROBE_DATA(probeCageProbe(f, cage, corner)));
}

// The cage of cascade c around the receiver x (its corners not looked at yet): the receiver
// biased against self-shadowing, and the cage's base corner and trilinear position around it.
ProbeCage probeCageAt(uint c, vec3 x, vec3 n, vec3 view) {
  ProbeVolume v = PROBE_VOLUME(c);
  float spacing = v.originSpacing.w;
  ProbeCage cage;
  cage.cascade = c;
  cage.biased = x + probeSelfShadowBias(n, view, spacing, v.visibility.x);
  vec3 g = (cage.biased - vec3(v.originSpacing)) / spacing;
  ivec3 maxBase = ivec3(max(int(v.countsRays.x) - 2, 0), max(int(v.countsRays.y) - 2, 0),
                        max(int(v.countsRays.z) - 2, 0));
  cage.base = clamp(ivec3(floor(g)), ivec3(0), maxBase);
  cage.alpha = clamp(g - vec3(cage.base), vec3(0.0f), vec3(1.0f));
  cage.usable = 0u;
  cage.traceMask = 0u;
  for (uint corner = 0u; corner < 8u; ++corner) cage.weight[corner] = 0.0f;
  return cage;
}

// M21 Sec. 2.2 and 4.1 / H22 Sec. 4.4: one corner of the cage around the biased receiver,
// weighted by backface (wrap) x visibility (Chebyshev on the depth moments towards the biased
// receiver, and/or the SDF test). Returns (weight so far, 1 when the SDF test is open and must
// be traced, 1 when the probe is usable): probes that are off or were never updated are not;
// relocated probes are used at their relocated positions.
vec3 probeCornerWeight(ProbeFrame f, ProbeCage cage, uint corner, vec3 x, vec3 n,
                       bool sdfVisibility) {
  uint probe = probeCageProbe(f, cage, corner);
  vec4 data = PROBE_DATA(probe);
  if (probeStateOf(data) == kProbeOff) return vec3(0.0f);
  if (PROBE_IRRADIANCE(probeIrradianceIndex(probe, uvec2(1u, 1u))).w == 0.0f) return vec3(0.0f);
  ProbeVolume v = PROBE_VOLUME(cage.cascade);
  vec3 p = probeGridPosition(v, probeCageCorner(v, cage, corner)) + vec3(data);
  vec3 toProbe = p - x;
  float lenToProbe = length(toProbe);
  vec3 dirToProbe = lenToProbe > 1e-6f ? toProbe / lenToProbe : n;
  float w = probeBackfaceWeight(dirToProbe, n);
  vec3 fromProbe = cage.biased - p;
  float r = length(fromProbe);
  vec3 dirFromProbe = r > 1e-6f ? fromProbe / r : n;
  vec2 moments = vec2(0.0f);
  float chebyshev = 1.0f;
  if ((f.options.x & kProbeOptionNoChebyshev) == 0u) {
    moments = probeSampleDepth(probe, dirFromProbe);
    chebyshev = probeChebyshevWeight(moments, r, v.visibility.w);
  }
  w *= chebyshev;
  if (!sdfVisibility) return vec3(w, 0.0f, 1.0f);
  float presumed = probeSdfVisibilityPresumed(f, moments, r, chebyshev);
  return presumed >= 0.0f ? vec3(w * presumed, 0.0f, 1.0f) : vec3(w, 1.0f, 1.0f);
}

// A usable corner's part of the cage's estimate once its weight is final (the SDF test's answer
// included): the weight crushed below kProbeCrushThreshold, times trilinear; (irradiance x
// weight, weight).
vec4 probeCornerContribution(ProbeFrame f, ProbeCage cage, uint corner, vec3 n, float w) {
  w = probeCrushWeight(max(w, 1e-6f), kProbeCrushThreshold);
  w *= probeTrilinearWeight(cage.alpha, corner);
  vec3 e = probeSampleIrradiance(probeCageProbe(f, cage, corner), n,
                                 PROBE_VOLUME(cage.cascade).blend.w);
  return vec4(e * w, w);
}

// The cage with every corner weighed and its open SDF tests listed (traced by the caller).
ProbeCage probeCagePlan(ProbeFrame f, uint c, vec3 x, vec3 n, vec3 view, bool sdfVisibility) {
  ProbeCage cage = probeCageAt(c, x, n, view);
  for (uint corner = 0u; corner < 8u; ++corner) {
    vec3 cw = probeCornerWeight(f, cage, corner, x, n, sdfVisibility);
    if (cw.z == 0.0f) continue;
    cage.usable |= 1u << corner;
    if (cw.y != 0.0f) cage.traceMask |= 1u << corner;
    cage.weight[corner] = cw.x;
  }
  return cage;
}

// The SDF test of one open corner towards `receiver` (the cage's own biased receiver, or a
// neighbour's that shares the cage): 1 where the probe sees it, else 1e-4 (probeSdfVisibility).
float probeCageSdfVisibility(ProbeFrame f, ProbeCage cage, uint corner, vec3 receiver) {
  return probeSdfVisibility(f, cage.cascade, probeCageProbePosition(f, cage, corner), receiver);
}

// The cage's estimate once its open SDF tests are answered (bit per corner of `visible`, read
// where traceMask is set): rgb and the summed weight (0 when no probe of the cage is usable).
vec4 probeCageIrradiance(ProbeFrame f, ProbeCage cage, vec3 n, uint visible) {
  vec4 sum = vec4(0.0f);
  for (uint corner = 0u; corner < 8u; ++corner) {
    if ((cage.usable & (1u << corner)) == 0u) continue;
    float w = cage.weight[corner];
    if ((cage.traceMask & (1u << corner)) != 0u) w *= (visible & (1u << corner)) != 0u ? 1.0f : 1e-4f;
    sum += probeCornerContribution(f, cage, corner, n, w);
  }
  return sum.w > 0.0f ? vec4(vec3(sum) / sum.w, sum.w) : vec4(0.0f);
}

// The open SDF tests of a cage, traced towards `receiver`: bit per corner of `corners` that sees
// it. One trace per iteration, the lowest corner left: lanes of a warp with different corners
// trace side by side, so the warp runs as many traces as its busiest lane (a loop over corner
// ids would run every corner any lane needs, one after the other). Only the visibility bits
// come back: a build that also summed the traces' steps here cost 0.6 of 4.0 ms on the H100
// (docs/GPU_BUDGET.md).
uint probeCageTrace(ProbeFrame f, ProbeCage cage, uint corners, vec3 receiver) {
  uint visible = 0u;
  uint left = corners;
  while (left != 0u) {
    uint corner = uint(findLSB(left));
    left &= left - 1u;
    if (probeCageSdfVisibility(f, cage, corner, receiver) == 1.0f) visible |= 1u << corner;
  }
  return visible;
}

// One volume's estimate in one pass (each open SDF test traced where it comes up): rgb and the
// summed weight (0 when no probe of the cage is usable). The probe trace pass's multi-bounce
// lookup and engines' per-pixel shaders use this; probe_sample.comp plans first (below).
vec4 probeVolumeIrradiance(ProbeFrame f, uint c, vec3 x, vec3 n, vec3 view, bool sdfVisibility) {
  ProbeCage cage = probeCageAt(c, x, n, view);
  vec4 sum = vec4(0.0f);
  for (uint corner = 0u; corner < 8u; ++corner) {
    vec3 cw = probeCornerWeight(f, cage, corner, x, n, sdfVisibility);
    if (cw.z == 0.0f) continue;
    float w = cw.x;
    if (cw.y != 0.0f) w *= probeCageSdfVisibility(f, cage, corner, cage.biased);
    sum += probeCornerContribution(f, cage, corner, n, w);
  }
  return sum.w > 0.0f ? vec4(vec3(sum) / sum.w, sum.w) : vec4(0.0f);
}

// The share cascade c takes of the receiver x in probeFieldIrradiance's walk from fine to
// coarse, or -1 when x is not at least half a spacing inside c's probe grid (and c is not the
// last): the finest cascade that holds x blends over the next spacing into the next coarser one.
float probeCascadeShare(ProbeFrame f, uint c, vec3 x) {
  ProbeVolume v = PROBE_VOLUME(c);
  vec3 g = (x - vec3(v.originSpacing)) / v.originSpacing.w;
  vec3 hi = vec3(float(v.countsRays.x) - 1.0f, float(v.countsRays.y) - 1.0f,
                 float(v.countsRays.z) - 1.0f) - g;
  float edge = min(min(min(g.x, g.y), g.z), min(min(hi.x, hi.y), hi.z));
  bool last = c + 1u == f.counts.x;
  if (edge <= 0.5f && !last) return -1.0f;
  return last ? 1.0f : clamp(edge - 0.5f, 0.0f, 1.0f);
}

// The walk of probeFieldIrradiance from cascade `first` on: each cascade that holds x adds its
// estimate times its share of what the finer ones left (sum), until nothing remains.
struct ProbeCascadeBlend {
  vec3 sum;
  float remaining;
};

ProbeCascadeBlend probeCascadeWalk(ProbeFrame f, uint first, vec3 x, vec3 n, vec3 view,
                                   bool sdfVisibility, ProbeCascadeBlend blend) {
  for (uint c = first; c < f.counts.x && blend.remaining > 0.0f; ++c) {
    float w = probeCascadeShare(f, c, x);
    if (w < 0.0f) continue;
    vec4 e = probeVolumeIrradiance(f, c, x, n, view, sdfVisibility);
    if (e.w <= 0.0f) continue;
    blend.sum += vec3(e) * (blend.remaining * w);
    blend.remaining *= 1.0f - w;
  }
  return blend;
}

vec3 probeCascadeBlendResult(ProbeCascadeBlend blend) {
  float used = 1.0f - blend.remaining;
  return used > 0.0f ? blend.sum / used : vec3(0.0f);
}

// The field's irradiance at x (cascade-0 voxels) for unit normal n seen from view: the finest
// cascade whose probe grid holds x at least half a spacing inside, blended over the next spacing
// into the next coarser cascade (a smooth band, no seams where cascades meet; GS "cascades").
// onlyCascade >= 0 samples that cascade alone (tests and debugging).
vec3 probeFieldIrradiance(ProbeFrame f, vec3 x, vec3 n, vec3 view, bool allowSdfVisibility,
                          int onlyCascade) {
  bool sdfVisibility = allowSdfVisibility && (f.options.x & kProbeOptionSdfVisibility) != 0u;
  if (onlyCascade >= 0) return vec3(probeVolumeIrradiance(f, uint(onlyCascade), x, n, view, sdfVisibility));
  ProbeCascadeBlend blend;
  blend.sum = vec3(0.0f);
  blend.remaining = 1.0f;
  return probeCascadeBlendResult(probeCascadeWalk(f, 0u, x, n, view, sdfVisibility, blend));
}

// ---- Sampling with shared SDF tests (probe_sample.comp) ---------------------------------------
// probeFieldIrradiance in three steps, so that neighbouring receivers can split their SDF
// traces: plan the cages (no traces), trace (each receiver its own open corners, or a share of
// its group's), finish. A receiver needs at most two cages (one in a blend band); a plan that
// would need more (a cage with no usable probe on the way) finishes the rest unshared.
struct ProbeFieldPlan {
  ProbeCage cage[2];
  float share[2];
  uint count;
  uint resume;  // 0: the plan is complete; else the cascade to carry on from, + 1
};

ProbeFieldPlan probeFieldPlan(ProbeFrame f, vec3 x, vec3 n, vec3 view, int onlyCascade) {
  bool sdfVisibility = (f.options.x & kProbeOptionSdfVisibility) != 0u;
  ProbeFieldPlan plan;
  plan.count = 0u;
  plan.resume = 0u;
  plan.share[0] = 0.0f;
  plan.share[1] = 0.0f;
  if (onlyCascade >= 0) {
    plan.cage[0] = probeCagePlan(f, uint(onlyCascade), x, n, view, sdfVisibility);
    plan.share[0] = -1.0f;  // the cage's estimate as it is (probeFieldIrradiance's onlyCascade)
    plan.count = 1u;
    return plan;
  }
  float remaining = 1.0f;
  for (uint c = 0u; c < f.counts.x; ++c) {
    float w = probeCascadeShare(f, c, x);
    if (w < 0.0f) continue;
    if (plan.count == 2u) {
      plan.resume = c + 1u;
      break;
    }
    ProbeCage cage = probeCagePlan(f, c, x, n, view, sdfVisibility);
    if (cage.usable == 0u) continue;
    // Constant indices only: an array indexed by a variable lives in local memory on NVIDIA
    // (the driver's resource report gave this pass 832 bytes of it a thread).
    if (plan.count == 0u) {
      plan.cage[0] = cage;
      plan.share[0] = w;
    } else {
      plan.cage[1] = cage;
      plan.share[1] = w;
    }
    plan.count += 1u;
    remaining *= 1.0f - w;
    if (remaining <= 0.0f) break;
  }
  return plan;
}

// Cage i of a plan by constant indices only (see probeFieldPlan): plan.cage[i] with i a loop
// variable would keep the plan in local memory wherever the loop is not unrolled.
ProbeCage probePlanCage(ProbeFieldPlan plan, uint i) {
  if (i == 0u) return plan.cage[0];
  return plan.cage[1];
}

// The plan's irradiance once its cages' open SDF tests are answered (visible0/1: bit per corner).
// The same arithmetic, in the same order, as probeFieldIrradiance.
vec3 probeFieldFinish(ProbeFrame f, ProbeFieldPlan plan, vec3 x, vec3 n, vec3 view,
                      uint visible0, uint visible1) {
  if (plan.share[0] < 0.0f) return vec3(probeCageIrradiance(f, plan.cage[0], n, visible0));
  ProbeCascadeBlend blend;
  blend.sum = vec3(0.0f);
  blend.remaining = 1.0f;
  for (uint i = 0u; i < 2u; ++i) {  // a constant trip count, unrolled (see probeFieldPlan)
    if (i >= plan.count) break;
    float share = i == 0u ? plan.share[0] : plan.share[1];
    vec4 e = probeCageIrradiance(f, probePlanCage(plan, i), n, i == 0u ? visible0 : visible1);
    blend.sum += vec3(e) * (blend.remaining * share);
    blend.remaining *= 1.0f - share;
  }
  if (plan.resume > 0u) {
    bool sdfVisibility = (f.options.x & kProbeOptionSdfVisibility) != 0u;
    blend = probeCascadeWalk(f, plan.resume - 1u, x, n, view, sdfVisibility, blend);
  }
  return probeCascadeBlendResult(blend);
}

// Whether a group of receivers (kProbeSampleShareLanes consecutive queries: neighbouring pixels
// of a view) shares cage i's SDF tests: every one plans the same cage (cascade and corner 0) there,
// and the biased receivers lie within half a voxel of that cascade of the first one's. Each then
// traces its share of the union of their open corners towards its own receiver, and all read
// every answer: a probe that sees one receiver sees the others half a voxel away (the traces' own
// hit epsilon is of that order).
bool probeGroupSharesCage(ProbeCage lead, ProbeCage other) {
  if (lead.cascade != other.cascade || lead.base != other.base) return false;
  float tolerance = 0.5f * SDF_CASCADE(lead.cascade).offsetScale.w;
  vec3 d = abs(other.biased - lead.biased);
  return max(max(d.x, d.y), d.z) <= tolerance;
}

// The corners of `corners` that group lane `lane` traces for the group: every
// kProbeSampleShareLanes-th set bit from lane's on (its share, rounded up).
uint probeGroupLaneCorners(uint corners, uint lane) {
  uint mine = 0u;
  uint rank = 0u;
  for (uint corner = 0u; corner < 8u; ++corner) {
    if ((corners & (1u << corner)) == 0u) continue;
    if (rank % kProbeSampleShareLanes == lane) mine |= 1u << corner;
    rank += 1u;
  }
  return mine;
}
