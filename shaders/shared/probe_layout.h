// Probe GI (DDGI) constants and the per-volume GPU struct, shared by C++ and GLSL (STYLE.md
// habit 1). The math that uses them is shaders/probe_math.glsl.
//
// Probe texture layout (Majercik 2021 Sec. 7, Fig. 12; Hvezda 2022 Sec. 4.5, Fig. 4.9): each
// probe owns one square tile per texture, an octahedral map (Cigolle 2014) of `interior` texels
// per edge surrounded by a 1-texel border. Tile texel (x, y), x,y in [0, interior + 2):
//   - x,y in [1, interior]: interior texel (x-1, y-1), centre at octahedral coordinate
//     ((x - 1 + 0.5) / interior) * 2 - 1 (see probeTexelCentreOct).
//   - x or y == 0 or interior+1: border, a copy of one interior texel (probeBorderSource), so
//     that hardware bilinear filtering across the octahedral seams reads the right neighbour.
// Irradiance: 8x8 interior + border = 10x10 texels, RGB stored as irradiance^(1/5) (perceptual
// encoding, Majercik 2021 Sec. 4.2). Depth: 14x14 interior + border = 16x16 texels, RG = mean and
// mean of the squared ray distance (Majercik 2021 Sec. 2.3), in cascade voxels.
//
// Units: positions and distances handed to the GPU are cascade-0 voxels relative to cascade 0's
// minimum corner (sdf_layout.h), like the stack traversal's rays.
#ifndef SDFSTREAM_PROBE_LAYOUT_H
#define SDFSTREAM_PROBE_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"

SDF_BEGIN_NAMESPACE

SDF_CONST uint kProbeGridDefault = 17;        // probes per volume edge (17³ = 4913 probes)
SDF_CONST uint kProbeSpacingCells = 8;        // probe spacing in cascade cells (one brick)
SDF_CONST uint kProbeBorderTexels = 1;        // border width of every octahedral tile
SDF_CONST uint kProbeIrradianceInterior = 8;  // irradiance interior texels per edge
SDF_CONST uint kProbeIrradianceTexels = 10;   // 8 + 2 * border
SDF_CONST uint kProbeDepthInterior = 14;      // depth-moment interior texels per edge
SDF_CONST uint kProbeDepthTexels = 16;        // 14 + 2 * border
SDF_CONST uint kProbeDefaultRays = 128;       // rays per probe per update

// Defaults (each is a field of ProbeVolume so a volume can override it).
SDF_CONST float kProbeIrradianceGamma = 5.0f;  // perceptual exponent (Majercik 2021 Sec. 4.2)
SDF_CONST float kProbeDepthSharpness = 50.0f;  // power-cosine exponent of the depth blend
SDF_CONST float kProbeDefaultHysteresis = 0.97f;
SDF_CONST float kProbeDefaultSelfShadowBias = 0.3f;  // B in Majercik 2021 Eq. 2 (Sec. 4.1)
SDF_CONST float kProbeBackfaceDepthScale = 0.2f;     // backface hits: depth shortened by 80% (4.1)
SDF_CONST float kProbeMinVariance = 1e-4f;           // Chebyshev variance clamp, voxels²
// Corner weights below this are crushed (w^3 / c^2; Majercik 2019 and H22 Eq. 4.10 use 0.2). A
// lighter crush keeps the light of corners Chebyshev finds barely visible; it goes with the
// relocation clearance (ProbeFieldSettings::relocationMinDistance), which trades the same light
// (docs/DECISIONS.md, "Corner weights crushed below 0.1, not 0.2" and "Clearance 0.15, crush
// 0.05").
SDF_CONST float kProbeCrushThreshold = 0.05f;
// Moving objects whose bounding radius is below this fraction of the spacing move no probe (they
// shade little of a probe's sphere, and each move flushes the probe's hit cache); the stress
// scene's cost was measured with this rule (docs/DECISIONS.md, "Probes near moving objects:
// relocated away from them, alive beside them"). Larger ones keep the static clearance free.
SDF_CONST float kProbeObjectMinRadius = 0.2f;

// Probe states (M21 Sec. 5, "probe classification"), stored in ProbeData.w as a float.
SDF_CONST uint kProbeOff = 0u;       // inside geometry or no surface within its cage: never traced
SDF_CONST uint kProbeSleeping = 1u;  // converged and unchanged: refreshed every sleepPeriod frames
SDF_CONST uint kProbeAwake = 2u;     // traced every frame its schedule allows
SDF_CONST uint kProbeVigilant = 3u;  // just entered, or lights changed: every frame, low hysteresis

// Update priority classes (probe_select.comp): lower is more urgent. The frame's ray budget is
// filled class by class; the first class that does not fit whole is dropped whole, so the set
// of traced probes never depends on GPU thread order (identical seeds, identical results).
SDF_CONST uint kProbeClassCount = 4u;
SDF_CONST uint kProbeClassNone = 255u;  // not wanted this frame

// Hit cache entry flags (uvec2 per (probe, rotation slot, ray); x = t in cascade-0 voxels as
// float bits, y = flags | cascade << 2 | octahedral normal (13 + 13 bits) << 6).
SDF_CONST uint kHitCacheValid = 1u;
SDF_CONST uint kHitCacheHit = 2u;  // clear: the ray left the stack (sky)

// One probe volume (one per SDF cascade). 16-byte boundaries marked; only vec4/uvec4/ivec4.
// All volumes share the probe storage buffers: global probe g = cascade * probesPerVolume + s,
// with s the toroidal storage index of the probe inside its volume.
struct ProbeVolume {
  vec4 originSpacing;    // xyz: logical probe (0,0,0), cascade-0 voxels (this frame);
                         // w: spacing, cascade-0 voxels                               (0..15)
  uvec4 countsRays;      // xyz: probes per axis; w: rays per probe                     (16..31)
  ivec4 scroll;          // xyz: storage coordinate of logical probe (0,0,0) (toroidal);
                         // w: cascade index                                            (32..47)
  ivec4 moved;           // xyz: grid shift since last frame (probes); w: 1 = volume reset (48..63)
  vec4 blend;            // x: irradiance hysteresis, y: depth hysteresis, z: max ray distance
                         // (misses record it), w: irradiance gamma                     (64..79)
  vec4 visibility;       // x: self-shadow bias B, y: depth sharpness, z: backface depth scale,
                         // w: Chebyshev minimum variance                              (80..95)
  vec4 prevWindow;       // xyz: this cascade's SDF window min corner last frame, in this
                         // frame's cascade-0 voxels; w: window edge (cascade-0 voxels) (96..111)
};

// Per-frame constants of the probe field passes (one-element storage buffer).
struct ProbeFrame {
  vec4 skyZenith;        // rgb: sky radiance straight up; w: bounce gain               (0..15)
  vec4 skyHorizon;       // rgb: sky radiance at/below the horizon; w: voxel size 0 (m) (16..31)
  vec4 camera;           // xyz: camera, cascade-0 voxels; w: cos(half field of view)   (32..47)
  vec4 view;             // xyz: unit view direction; w: vigilant hysteresis            (48..63)
  uvec4 counts;          // x: cascades, y: probes per volume, z: lights, w: ray budget  (64..79)
  uvec4 options;         // x: kProbeOption* bits, y: frame, z: sleep period, w: trace max steps
  vec4 trace;            // x: hit epsilon, y: relocation min distance (fraction of spacing),
                         // z: sleep threshold (relative change), w: rays cap (trace tMax) (96..111)
  uvec4 selection;       // x: cutoff class (select emit; kProbeClassCount = all), y: list capacity,
                         // z: rotation slots of the hit cache, w: vigilant frames after a
                         // change (bits 0-7) / near a moving object (bits 8-15)      (112..127)
  vec4 worldToStack;     // xyz: cascade 0's minimum corner, world metres; w: 1 / cascade-0 voxel
                         // size (1/m): stack = (world - xyz) * w, as CascadeStackImage::toStack;
                         // engines' world-space queries (sdfstream/probe_sample.glsl) (128..143)
  uvec4 bounce;          // the bounce cells (probe_trace.glsl): x: this update's stamp (updates
                         // since the field's reset), y: updates a cell's bounce serves (0: every
                         // hit looks the probes up itself), z: first work item of the
                         // rays' list (list capacity x rays), w: 0                  (144..159)
};

SDF_CONST uint kProbeOptionHitCache = 1u;
SDF_CONST uint kProbeOptionStates = 2u;
SDF_CONST uint kProbeOptionRelocation = 4u;
SDF_CONST uint kProbeOptionSdfVisibility = 8u;  // SDFDDGI's SDF visibility test when sampling
SDF_CONST uint kProbeOptionNoChebyshev = 256u;  // ... instead of (not on top of) Chebyshev
SDF_CONST uint kProbeOptionLightsChanged = 16u;
SDF_CONST uint kProbeOptionAdaptiveHysteresis = 32u;
SDF_CONST uint kProbeOptionFirstFrame = 64u;    // reset every probe (first frame, settings)
SDF_CONST uint kProbeOptionCacheCheck = 128u;   // a window scrolled or pages changed: validate
SDF_CONST uint kProbeOptionObjects = 512u;      // moving objects are bound (object_bindings.glsl)
SDF_CONST uint kProbeOptionObjectsNaive = 1024u;  // every ray against every object (stress peer)
SDF_CONST uint kProbeOptionBackfacesBlack = 2048u;  // blend backface rays as black radiance
SDF_CONST uint kProbeOptionSdfEverywhere = 4096u;  // SDF visibility for every corner, not only
                                                   // where Chebyshev is unsure (probe_sample.glsl)
// The lights changed a little (ProbeFieldSettings::lightDriftDegrees): no probe wakes; a sleeping
// probe's refresh blends as much as an awake probe would over its sleep period.
SDF_CONST uint kProbeOptionLightsDrifting = 8192u;
SDF_CONST uint kProbeOptionDriftedBefore = 16384u;  // ... and so they did in the last frame
// probe_sample.comp: every query traces its own SDF tests (no group shares them), as a per-pixel
// shader does.
SDF_CONST uint kProbeOptionSdfPerQuery = 32768u;
// Bits 16..19: the region cascades listing an object (above every option bit; the mask once
// shared bit 12 with kProbeOptionSdfEverywhere, which turned SDF visibility on everywhere
// whenever cascade 0 listed an object).
SDF_CONST uint kProbeObjectMaskShift = 16u;
// The atlas binding holds the corner atlas (gi/gpu_stack_scene.h), not the distance atlas.
SDF_CONST uint kProbeOptionCellCorners = 1048576u;  // bit 20, above the object mask

// Push constants of every probe field pass: which sub-pass, how many threads.
SDF_CONST uint kProbeSelectModeCount = 0u;    // probe_select.comp: count wanted probes per class
SDF_CONST uint kProbeSelectModeEmit = 1u;     // probe_select.comp: append probes below the cutoff
SDF_CONST uint kProbeSelectModeArgs = 2u;     // probe_select.comp: size the list-driven passes
SDF_CONST uint kProbeBounceModeCells = 0u;    // probe_bounce.comp: look up the listed cells
SDF_CONST uint kProbeBounceModeRays = 1u;     // probe_bounce.comp: add the waiting rays' terms
SDF_CONST uint kProbeBounceModeOwn = 2u;      // probe_bounce.comp: the rays' own lookups
SDF_CONST uint kProbeBlendTexelsPerProbe = 260u;  // 8² irradiance + 14² depth interior texels
SDF_CONST uint kProbeBlendThreadsPerProbe = 64u;  // the interior blend: one workgroup per probe
// The depth blend's ray lists (probe_update.glsl, "Depth texels' ray lists"): every probe of a
// frame casts the same pattern, so a depth texel's power-cosine weights are frame constants. Per
// depth interior texel, the rays whose weight is at least kProbeDepthListFloor of its nearest
// ray's (13 a texel on average at sharpness 50 over 32-256 rays; the mean depth moves < 1e-3), in
// ray order, at most kProbeDepthListRays; a texel with more (a wide lobe, many rays) is marked
// dense and blends every ray. They follow the rotations in the ray-pattern buffer, a set per
// rotation slot (slot-major; a probe's update takes its own slot, probeHistorySlot), one block of
// kProbeDepthListVec4s vec4 per texel: x of the first = the count (uint bits, or
// kProbeDepthListDense), then (ray, weight) pairs, two per vec4 (ray as uint bits).
SDF_CONST uint kProbeDepthListRays = 32u;
SDF_CONST uint kProbeDepthListVec4s = 17u;  // 1 + kProbeDepthListRays / 2
SDF_CONST uint kProbeDepthListDense = 0xffffffffu;
SDF_CONST float kProbeDepthListFloor = 3e-5f;  // of the texel's nearest ray's weight
// probe_sample.comp: consecutive queries (neighbouring pixels) that split the SDF tests of a
// cage they share (a power of two dividing the workgroup's 64). 8: a 4×2 pixel block in tile
// order, so each lane traces at most one of the cage's 8 corners; against 4 (2×2 quads), Sponza
// at 1080p on an H100 2.055 -> 1.878 ms (docs/GPU_BUDGET.md, "queries in pixel tiles").
SDF_CONST uint kProbeSampleShareLanes = 8u;

struct ProbePushConstants {
  // x: mode, y: threads of this dispatch; sampling at half resolution (probe_sample.comp's
  // kHalfImage variant, probe_upsample.comp): z, w = the full-resolution image's width and height
  uvec4 dispatch;
};

// Frame statistics (one storage buffer of uints, atomically accumulated on the GPU).
SDF_CONST uint kProbeStatClassCounts = 0u;  // [0, 4): wanted probes per class
SDF_CONST uint kProbeStatListCount = 4u;    // probes appended to this frame's update list
SDF_CONST uint kProbeStatRaysTraced = 5u;   // rays sphere-traced this frame
SDF_CONST uint kProbeStatRaysCached = 6u;   // rays answered by the hit cache
SDF_CONST uint kProbeStatSteps = 7u;        // sphere-tracing steps this frame
SDF_CONST uint kProbeStatStates = 8u;       // [8, 12): probes per state after classify
SDF_CONST uint kProbeStatCacheInvalidated = 12u;
SDF_CONST uint kProbeStatObjectRays = 13u;   // rays that searched the moving objects
SDF_CONST uint kProbeStatObjectHits = 14u;   // ... and hit one before the static scene
SDF_CONST uint kProbeStatObjectSteps = 15u;  // object sphere-tracing steps
SDF_CONST uint kProbeStatBounceCells = 16u;  // bounce cells looked up afresh this update
SDF_CONST uint kProbeStatBounceRays = 17u;   // rays that waited for a bounce cell, or had none
SDF_CONST uint kProbeStatBounceOwn = 18u;    // ... of them, those that look up their own
SDF_CONST uint kProbeStatCount = 19u;

// A bounce cell (probe_trace.glsl, "Bounce cells"): per static material voxel, the probe field's
// irradiance at its surface point, uvec2(RGB9E5 irradiance, word). The word: valid, pending (a
// ray claimed the cell's lookup this update), surface (the cell has a surface point; else every
// hit there looks the probes up itself), the 16-bit stamp of the update that looked it up, and
// the cell's normal (octahedral, 6 + 6 bits).
SDF_CONST uint kBounceCellValid = 0x80000000u;
SDF_CONST uint kBounceCellPending = 0x40000000u;
SDF_CONST uint kBounceCellSurface = 0x20000000u;
SDF_CONST uint kBounceCellStampShift = 12u;
SDF_CONST uint kBounceCellNormalMask = 0xfffu;

// One irradiance query of probe_sample.comp (irradiance(x, n, view) of the field).
struct ProbeQuery {
  vec4 position;  // xyz: receiver, cascade-0 voxels; w: 0 = all cascades, 1 + c = c alone (0..15)
  vec4 normal;    // xyz: unit surface normal; w unused                                (16..31)
  vec4 view;      // xyz: unit direction from the receiver towards the camera; w unused (32..47)
};

SDF_END_NAMESPACE

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(sdfstream::gpu_shared::ProbeVolume) == 112);
static_assert(offsetof(sdfstream::gpu_shared::ProbeVolume, countsRays) == 16);
static_assert(offsetof(sdfstream::gpu_shared::ProbeVolume, blend) == 64);
static_assert(offsetof(sdfstream::gpu_shared::ProbeVolume, prevWindow) == 96);
static_assert(sizeof(sdfstream::gpu_shared::ProbeFrame) == 160);
static_assert(offsetof(sdfstream::gpu_shared::ProbeFrame, bounce) == 144);
static_assert(offsetof(sdfstream::gpu_shared::ProbeFrame, selection) == 112);
static_assert(offsetof(sdfstream::gpu_shared::ProbeFrame, worldToStack) == 128);
static_assert(sizeof(sdfstream::gpu_shared::ProbePushConstants) == 16);
static_assert(sdfstream::gpu_shared::kProbeOptionSdfPerQuery <
              (1u << sdfstream::gpu_shared::kProbeObjectMaskShift));  // no option in the mask
static_assert(sdfstream::gpu_shared::kProbeOptionCellCorners ==
              (1u << (sdfstream::gpu_shared::kProbeObjectMaskShift +
                      4u)));  // past the mask's 4 bits
static_assert(sizeof(sdfstream::gpu_shared::ProbeQuery) == 48);
static_assert(sdfstream::gpu_shared::kProbeBlendTexelsPerProbe ==
              sdfstream::gpu_shared::kProbeIrradianceInterior *
                      sdfstream::gpu_shared::kProbeIrradianceInterior +
                  sdfstream::gpu_shared::kProbeDepthInterior *
                      sdfstream::gpu_shared::kProbeDepthInterior);
static_assert(sdfstream::gpu_shared::kProbeIrradianceInterior +
                  2 * sdfstream::gpu_shared::kProbeBorderTexels ==
              sdfstream::gpu_shared::kProbeIrradianceTexels);
static_assert(sdfstream::gpu_shared::kProbeDepthInterior +
                  2 * sdfstream::gpu_shared::kProbeBorderTexels ==
              sdfstream::gpu_shared::kProbeDepthTexels);
static_assert(sdfstream::gpu_shared::kProbeDepthListVec4s ==
              1 + sdfstream::gpu_shared::kProbeDepthListRays / 2);
#endif

#endif
