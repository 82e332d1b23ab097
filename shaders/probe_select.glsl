// Probe field, select pass (probe_select.comp; shaders/probe_field.glsl lists the pass files):
// which probes this frame updates, within the ray budget, and the group counts of the passes
// that run over the resulting list. Reads and writes
//   PROBE_VOLUME(c), PROBE_DATA(g), PROBE_HISTORY(g) (as for the classify pass)
//   PROBE_LIST(i)            -> uint global probe at position i of this frame's update list
//   PROBE_STAT(i)            -> uint frame statistic i (kProbeStat*), read
//   PROBE_STAT_ADD(i, v)     -> atomic add, returns the previous value
//   PROBE_DISPATCH_ARGS(i)   -> uint word i of the indirect dispatch arguments

// ---- Scheduling (M21 Sec. 5; GS "Reducing update frequency on invisible probes") -------------

// Priority class of a probe this frame, or kProbeClassNone. Vigilant first; awake probes near the
// camera or in its view cone next; awake probes outside it every second frame; sleeping probes
// every sleepPeriod frames (staggered by probe so the load is even); probes waiting 32 frames or
// more jump to the front.
uint probeUpdateClass(ProbeFrame f, uint g, uint state, vec3 position, float spacing, uint age) {
  if (state == kProbeOff) return kProbeClassNone;
  if (state == kProbeVigilant) return 0u;
  uint frame = f.options.y;
  uint cls = kProbeClassNone;
  if (state == kProbeSleeping) {
    uint period = max(f.options.z, 1u);
    if ((frame + g) % period == 0u) cls = 3u;
  } else {
    vec3 toProbe = position - vec3(f.camera);
    float dist = length(toProbe);
    bool near = dist < 2.0f * spacing;
    bool inView = dist > 0.0f && dot(toProbe / dist, vec3(f.view)) >= f.camera.w;
    if (near || inView) cls = 1u;
    else if (((frame + g) & 1u) == 0u) cls = 2u;
  }
  if (age >= 32u) cls = 0u;
  return cls;
}

// ---- Pass body (one call per GPU invocation; the CPU reference loops over the same) ----------

uint probeSelectClass(ProbeFrame f, uint g) {
  uint c = g / f.counts.y;
  ProbeVolume v = PROBE_VOLUME(c);
  vec4 data = PROBE_DATA(g);
  vec3 p = probeGridPosition(v, probeLogicalCoord(v, g % f.counts.y)) + vec3(data);
  return probeUpdateClass(f, g, probeStateOf(data), p, v.originSpacing.w,
                          probeHistoryAge(PROBE_HISTORY(g)));
}

// Which probes of the wanted ones fit this frame's list, from the counts of the count sub-pass
// (every invocation computes the same): x = the first class that does not fit whole
// (kProbeClassCount: all fit); y = the share of that class taken, in units of 1/65536 (0: no
// room). The share aims at the room left less 1/32 of the list: the taken count spreads a few
// probes around its mean, within that slack in every case measured, so the list does not
// overflow and the probes taken do not depend on thread order (the emit pass's bound catches
// the rest). Integer arithmetic only: the CPU reference takes the same probes.
uvec2 probeSelectCutoff(ProbeFrame f) {
  uint total = 0u;
  for (uint cls = 0u; cls < kProbeClassCount; ++cls) {
    uint count = PROBE_STAT(kProbeStatClassCounts + cls);
    if (total + count > f.selection.y) {
      uint aim = f.selection.y - f.selection.y / 32u;
      uint room = aim > total ? aim - total : 0u;  // < count
      uint shift = 0u;                             // (room >> shift) << 16 must fit in 32 bits
      while ((count >> shift) >= 65536u) shift += 1u;
      return uvec2(cls, ((room >> shift) << 16u) / max(count >> shift, 1u));
    }
    total += count;
  }
  return uvec2(kProbeClassCount, 0u);
}

// Whether probe g of the cutoff class is taken this frame, given the class's share (1/65536
// units): the point of g + frame in the golden-ratio (Weyl) sequence, below the share. Points of
// consecutive probes spread evenly over [0, 1), so about share x count of the class are taken
// however its probes lie in the field (a stride of ceil(count / room) took as few as half the
// room); and a probe's points in consecutive frames lie 0.618 apart, so at a share of 0.9 none
// is passed over twice in a row (one passed over 32 frames moves to class 0 anyway).
bool probeTakenInCutoffClass(uint g, uint frame, uint share) {
  return (((g + frame) * 0x9E3779B9u) >> 16u) < share;
}

// Group counts (x, y, 1) of a pass over `threads` invocations of 64, spread over rows of 16384
// groups like probeInvocation(), written at PROBE_DISPATCH_ARGS(at .. at + 2).
void probeWriteDispatch(uint at, uint threads) {
  uint groups = (threads + 63u) / 64u;
  uint rows = (groups + 16383u) / 16384u;
  PROBE_DISPATCH_ARGS(at) = rows > 1u ? 16384u : groups;
  PROBE_DISPATCH_ARGS(at + 1u) = max(rows, 1u);
  PROBE_DISPATCH_ARGS(at + 2u) = 1u;
}

// Dispatch sizes of the list-driven passes from this frame's list length (one invocation):
// trace (list x rays) at 0, blend (a workgroup of 64 per probe) at 3.
void probeWriteListDispatches(ProbeFrame f, uint raysPerProbe) {
  uint listed = min(PROBE_STAT(kProbeStatListCount), f.selection.y);
  probeWriteDispatch(0u, listed * raysPerProbe);
  probeWriteDispatch(3u, listed * kProbeBlendThreadsPerProbe);
}

// Select pass body (mode kProbeSelectModeCount or kProbeSelectModeEmit), one invocation per probe.
void probeSelectPass(ProbeFrame f, uint g, uint mode) {
  uint cls = probeSelectClass(f, g);
  if (cls >= kProbeClassCount) return;
  if (mode == kProbeSelectModeCount) {
    PROBE_STAT_ADD(kProbeStatClassCounts + cls, 1u);
    return;
  }
  uvec2 cutoff = probeSelectCutoff(f);
  if (cls > cutoff.x) return;
  if (cls == cutoff.x && !probeTakenInCutoffClass(g, f.options.y, cutoff.y)) return;
  uint index = PROBE_STAT_ADD(kProbeStatListCount, 1u);
  // Should the share overshoot even the list's slack, the list stays bounded, and the probes past
  // it (the only thread-order-dependent choice) wait for the next frame.
  if (index >= f.selection.y) return;
  PROBE_LIST(index) = g;
  PROBE_HISTORY(g) = probeHistoryListed(PROBE_HISTORY(g), f.selection.z);
}
