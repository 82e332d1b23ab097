// The storage macros of the probe field math and the includes it needs, in dependency order
// (the field's common part, then sampling, then one file per pass: shaders/probe_field.glsl).
// One file for both languages: the GLSL passes (probe_bindings.glsl) declare buffers with these
// names, and the CPU reference (gi/probe_field_cpu.cpp) declares members with the same names
// plus an atomicAdd(uint&, uint) member, then both include this inside their scope, so every pass
// and the reference compile the same math.
#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#include "shaders/sdf_trace.glsl"
#ifdef OBJ_FRAME  // moving objects: GLSL passes only (probe_bindings.glsl binds them)
#include "shaders/object_trace.glsl"
#include "shaders/card_math.glsl"
#include "shaders/card_lookup.glsl"
#endif
#include "shaders/probe_math.glsl"
#include "shaders/light_math.glsl"
#define PROBE_IRRADIANCE(i) irradiance[i]
#define PROBE_DEPTH(i) depth[i]
// A pass may read the blend's rays from elsewhere (probe_blend.comp: shared memory) by defining
// PROBE_RAY and PROBE_RAY_DIR first; PROBE_RAY_STORED is always the ray buffer.
#ifndef PROBE_RAY
#define PROBE_RAY(i) rays[i]
#define PROBE_RAY_DIR(i) rayDirs[i]
#endif
#define PROBE_RAY_STORED(i) rays[i]
#define PROBE_RAY_PATTERN(i) rayPattern[i]
#include "shaders/probe_update.glsl"
#define PROBE_VOLUME(c) volumes[c]
#define PROBE_DATA(g) probeData[g]
#define PROBE_HISTORY(g) history[g]
#define PROBE_CACHE(i) hitCache[i]
#define PROBE_ROTATION(r, k) PROBE_RAY_PATTERN((r) * 3u + (k))
#define PROBE_PAGE_CHANGED(c, i) (((pageChanged[(c) * 128u + ((i) >> 5u)] >> ((i) & 31u)) & 1u) != 0u)
#define LIGHT_RADIANCE(m) lightRadiance[m]
// Bounce cells (probe_trace.glsl): two words per material voxel, irradiance then the word the
// trace pass claims with a compare-and-swap.
#define LIGHT_BOUNCE_E(m) bounceCells[2u * (m)]
#define LIGHT_BOUNCE_WORD(m) bounceCells[2u * (m) + 1u]
#define LIGHT_BOUNCE_CLAIM(m, old, new) atomicCompSwap(bounceCells[2u * (m) + 1u], old, new)
#define PROBE_BOUNCE_WORK(i) bounceWork[i]
// The next free slot of list `i` (a counter among the stats): a pass may aggregate per subgroup
// (probe_bindings.glsl).
#ifndef PROBE_APPEND
#define PROBE_APPEND(i) PROBE_STAT_ADD(i, 1u)
#endif
#define PROBE_LIST(i) updateList[i]
#define PROBE_STAT(i) stats[i]
#define PROBE_STAT_ADD(i, v) atomicAdd(stats[i], v)
// A frame counter nobody reads back within the pass, at an index uniform over the invocations
// that reach the call: a pass may aggregate it (probe_bindings.glsl adds per subgroup first).
#ifndef PROBE_STAT_COUNT
#define PROBE_STAT_COUNT(i, v) PROBE_STAT_ADD(i, v)
#endif
#define PROBE_DISPATCH_ARGS(i) dispatchArgs[i]
#include "shaders/probe_field.glsl"
#include "shaders/probe_sample.glsl"
#include "shaders/probe_classify.glsl"
#include "shaders/probe_select.glsl"
#include "shaders/probe_trace.glsl"
#include "shaders/probe_near_field.glsl"
#include "shaders/probe_blend.glsl"
