// The probe field: one DDGI probe volume per SDF cascade. Its math is
// one file per pass, each the single definition that the GLSL passes include and that
// gi/probe_field_cpu.cpp includes as C++ inside a struct (the CPU reference, STYLE.md habit 9).
// shaders/probe_field_storage.glsl includes them in dependency order:
//   probe_field.glsl     this file: storage coordinates, probe state, hit-cache entries and the
//                        history word, shared by several passes
//   probe_sample.glsl    irradiance(x, n, view) across cascades (queries; multi-bounce shading)
//   probe_classify.glsl  scroll reset, SDF relocation, states, hit-cache invalidation
//   probe_select.glsl    scheduling, the update list and the sizes of the list-driven passes
//   probe_trace.glsl     a probe ray: hit cache or stack trace, shading
//   probe_near_field.glsl  a receiver's own short rays (sampling's near-field variant)
//   probe_blend.glsl     rays into interior texels, then borders
// Same rules as sdf_trace.glsl (no swizzles, no out parameters, f-suffixed float literals).
//
// The includer first includes shaders/shared/{sdf_layout,probe_layout}.h and
// shaders/probe_math.glsl; this file reads no storage. Each later file lists the storage macros
// it reads (PROBE_VOLUME(c) -> ProbeVolume of cascade c, PROBE_DATA(g), ... as lvalues).
//
// Global probe g = cascade * probesPerVolume + s; s is the probe's toroidal storage index in its
// volume: storage coordinate (s % nx, s / nx % ny, s / (nx ny)) holds logical probe
// storage - scroll (wrapped), which sits at originSpacing.xyz + logical * spacing + offset.
// PROBE_DATA(g) is a vec4: xyz relocation offset (cascade-0 voxels), w state (kProbe* as float).
//
// Seeds: Majercik et al. 2021 (M21), the Godot SDFGI slides (GS), Hu et al. 2022 SDFDDGI (SDFDDGI).

ivec3 probeStorageCoord(ProbeVolume v, uint s) {
  uint nx = v.countsRays.x;
  uint ny = v.countsRays.y;
  return ivec3(int(s % nx), int((s / nx) % ny), int(s / (nx * ny)));
}

// Toroidal wrap of one axis for values in [-n, 2n) (no % on negative ints: undefined in GLSL).
int probeWrap(int a, int n) {
  int r = a;
  if (r < 0) r += n;
  if (r >= n) r -= n;
  return r;
}

ivec3 probeLogicalCoord(ProbeVolume v, uint s) {
  ivec3 st = probeStorageCoord(v, s);
  return ivec3(probeWrap(st.x - v.scroll.x, int(v.countsRays.x)),
               probeWrap(st.y - v.scroll.y, int(v.countsRays.y)),
               probeWrap(st.z - v.scroll.z, int(v.countsRays.z)));
}

uint probeStorageIndex(ProbeVolume v, ivec3 logical) {
  int x = probeWrap(logical.x + v.scroll.x, int(v.countsRays.x));
  int y = probeWrap(logical.y + v.scroll.y, int(v.countsRays.y));
  int z = probeWrap(logical.z + v.scroll.z, int(v.countsRays.z));
  return uint(x) + v.countsRays.x * (uint(y) + v.countsRays.y * uint(z));
}

uint probeVolumeCount(ProbeVolume v) {
  return v.countsRays.x * v.countsRays.y * v.countsRays.z;
}

vec3 probeGridPosition(ProbeVolume v, ivec3 logical) {
  return vec3(v.originSpacing) + vec3(logical) * v.originSpacing.w;
}

uint probeStateOf(vec4 data) {
  return uint(data.w + 0.5f);
}

// ---- Hit cache entries (GS "Caching rays": cascade, position and normal of static hits) ----

uvec2 probeCacheEncode(bool hit, float t0, uint cascade, vec3 normal) {
  vec2 o = probeOctEncode(normal) * 0.5f + vec2(0.5f);
  uint ox = uint(clamp(o.x, 0.0f, 1.0f) * 8191.0f + 0.5f);
  uint oy = uint(clamp(o.y, 0.0f, 1.0f) * 8191.0f + 0.5f);
  uint flags = kHitCacheValid | (hit ? kHitCacheHit : 0u);
  return uvec2(floatBitsToUint(t0), flags | (cascade << 2u) | (ox << 6u) | (oy << 19u));
}

vec3 probeCacheNormal(uvec2 e) {
  vec2 o = vec2(float((e.y >> 6u) & 8191u), float((e.y >> 19u) & 8191u)) * (1.0f / 8191.0f);
  return probeOctDecode(o * 2.0f - vec2(1.0f));
}

uint probeCacheCascade(uvec2 e) {
  return (e.y >> 2u) & 7u;
}

// The hysteresis of a sleeping probe's refresh while the lights drift: as much of the fresh
// estimate as an awake probe takes over the sleep period ((1 - h) x period), but never more than
// a vigilant update takes. The field then follows a slowly moving sun at the awake rate without
// waking every probe (which costs the whole ray budget every frame).
float probeDriftHysteresis(ProbeFrame f, float h) {
  return max(f.view.w, 1.0f - (1.0f - h) * float(max(f.options.z, 1u)));
}

// The irradiance hysteresis of a vigilant update that leaves `left` (>= 1) vigilant updates after
// it: vigilantHysteresis, but when the vigilance came from a light switch (`closing`), its last
// vigilantMeanUpdates (selection.w bits 24-31) take a running mean of what the field held and
// their fresh estimates (1/2, 2/3, ...). Those span as many hit-cache rotations, and a vigilant
// texel holds mostly its last rotation's 128 directions, whose bias against the rotations' mean
// the closing mean removes. Only after a switch, whose catch-up has built the bounces up by then:
// a new probe's field may still be building (plain DDGI's Breakfast Room at its 32nd update),
// and the mean's slower blend kept 15% of its light out (E/E_ref 0.549 -> 0.466).
float probeVigilantHysteresis(ProbeFrame f, float h, uint left, bool closing) {
  uint meanUpdates = f.selection.w >> 24u;
  if (closing && left <= meanUpdates) return min(h, 1.0f - 1.0f / float(meanUpdates - left + 2u));
  return min(h, f.view.w);
}

// Probe history (uvec4): xyz mean irradiance at the last check (float bits); w packs
// quiet updates (bits 0..3), the hit-cache rotation slot of its latest update (4..7),
// vigilant updates left (8..15), frames since last update (16..29), bit 30: the vigilance came
// from a light switch (it closes with a mean, probeVigilantHysteresis), and bit 31: more than a
// quarter of its last rays hit backfaces (it sits inside geometry).
uint probeHistoryQuiet(uvec4 h) { return h.w & 15u; }
uint probeHistorySlot(uvec4 h) { return (h.w >> 4u) & 15u; }
uint probeHistoryVigilant(uvec4 h) { return (h.w >> 8u) & 255u; }
uint probeHistoryAge(uvec4 h) { return (h.w >> 16u) & 16383u; }
bool probeHistoryClosingMean(uvec4 h) { return ((h.w >> 30u) & 1u) != 0u; }
bool probeHistoryInside(uvec4 h) { return (h.w >> 31u) != 0u; }
uvec4 probeHistoryPack(vec3 mean, uint quiet, uint slot, uint vigilant, uint age,
                       bool closingMean, bool inside) {
  return uvec4(floatBitsToUint(mean.x), floatBitsToUint(mean.y), floatBitsToUint(mean.z),
               min(quiet, 15u) | ((slot & 15u) << 4u) | (min(vigilant, 255u) << 8u) |
                   (min(age, 16383u) << 16u) | (closingMean ? 0x40000000u : 0u) |
                   (inside ? 0x80000000u : 0u));
}

// The history of a probe listed for an update: age 0, and its next hit-cache rotation slot (of
// `slots`). Each probe steps through the slots one update at a time, whatever its schedule: a
// probe updated every second frame, or every eighth while asleep, once saw only the slots those
// frames took by frame number (one of four, asleep), and so held the bias of one rotation's 128
// directions instead of their mean.
uvec4 probeHistoryListed(uvec4 h, uint slots) {
  uint next = (probeHistorySlot(h) + 1u) % max(slots, 1u);
  return uvec4(h.x, h.y, h.z, (h.w & 0xc000ff0fu) | (next << 4u));
}

#ifdef OBJ_FRAME
// Whether rays of cascade-c probes may meet an object: objects are bound and some region
// cascade >= c lists one (bits of options.x from kProbeObjectMaskShift). Otherwise the trace is
// exactly the static-only path.
bool probeObjectsReach(ProbeFrame f, uint c) {
  if ((f.options.x & kProbeOptionObjects) == 0u) return false;
  uint mask = (f.options.x >> kProbeObjectMaskShift) & 15u;
  return (mask >> min(c, 31u)) != 0u;
}
#endif
