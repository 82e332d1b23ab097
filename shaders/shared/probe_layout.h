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
// Irradiance: 6x6 interior + border = 8x8 texels, RGB stored as irradiance^(1/5) (perceptual
// encoding, Majercik 2021 Sec. 4.2). Depth: 14x14 interior + border = 16x16 texels, RG = mean and
// mean of the squared ray distance (Majercik 2021 Sec. 2.3), in cascade voxels.
//
// Units: positions and distances handed to the GPU are cascade-relative voxels (sdf_layout.h).
#ifndef SDFSTREAM_PROBE_LAYOUT_H
#define SDFSTREAM_PROBE_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"

SDF_BEGIN_NAMESPACE

SDF_CONST uint kProbeGridDefault = 17;        // probes per volume edge (17³ = 4913 probes)
SDF_CONST uint kProbeSpacingCells = 8;        // probe spacing in cascade cells (one brick)
SDF_CONST uint kProbeBorderTexels = 1;        // border width of every octahedral tile
SDF_CONST uint kProbeIrradianceInterior = 6;  // irradiance interior texels per edge
SDF_CONST uint kProbeIrradianceTexels = 8;    // 6 + 2 * border
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

// One probe volume (one per SDF cascade). 16-byte boundaries marked; only vec4/uvec4/ivec4.
struct ProbeVolume {
  vec4 originSpacing;    // xyz: position of grid probe (0,0,0), cascade voxels; w: spacing (0..15)
  uvec4 countsRays;      // xyz: probes per axis; w: rays per probe                     (16..31)
  ivec4 scroll;          // xyz: toroidal storage offset of probe (0,0,0); w: frame index (32..47)
  vec4 rayRotationCol0;  // xyz: column 0 of this frame's ray rotation; w unused         (48..63)
  vec4 rayRotationCol1;  // xyz: column 1                                               (64..79)
  vec4 rayRotationCol2;  // xyz: column 2                                               (80..95)
  vec4 blend;            // x: irradiance hysteresis, y: depth hysteresis, z: max ray distance
                         // (misses record it), w: irradiance gamma                      (96..111)
  vec4 visibility;       // x: self-shadow bias B, y: depth sharpness, z: backface depth scale,
                         // w: Chebyshev minimum variance                               (112..127)
};

// Push constants of the probe update passes (probe_trace.comp, probe_blend.comp); the per-volume
// ProbeVolume above travels in a one-element storage buffer (it fills the guaranteed 128 bytes).
SDF_CONST uint kProbeBlendModeInterior = 0u;  // probe_blend.comp: blend rays into interior texels
SDF_CONST uint kProbeBlendModeBorder = 1u;    // probe_blend.comp: copy border texels
SDF_CONST uint kProbeBlendTexelsPerProbe = 232u;  // 6² irradiance + 14² depth interior texels
SDF_CONST uint kProbeTileTexelsPerProbe = 320u;   // 8² irradiance + 16² depth tile texels

struct ProbeUpdatePushConstants {
  vec4 skyBounce;   // xyz: sky radiance (linear RGB) a miss returns; w: bounce gain (0..1) (0..15)
  uvec4 counts;     // x: probe count, y: threads of this dispatch, z: trace max steps,
                    // w: cascade count                                                 (16..31)
  vec4 trace;       // x: hit epsilon (voxels), y: trace tMax (cascade-0 voxels), z: 1 = adaptive
                    // hysteresis (M21 Sec. 4.3), w unused                              (32..47)
  uvec4 mode;       // x: kProbeBlendMode* (probe_blend.comp); yzw unused               (48..63)
};

// One irradiance query of probe_sample.comp (irradiance(x, n, view) of a volume).
struct ProbeQuery {
  vec4 position;  // xyz: receiver, cascade-0 voxels; w unused                         (0..15)
  vec4 normal;    // xyz: unit surface normal; w unused                                (16..31)
  vec4 view;      // xyz: unit direction from the receiver towards the camera; w unused (32..47)
};

SDF_END_NAMESPACE

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(sdfstream::gpu_shared::ProbeVolume) == 128);
static_assert(offsetof(sdfstream::gpu_shared::ProbeVolume, countsRays) == 16);
static_assert(offsetof(sdfstream::gpu_shared::ProbeVolume, scroll) == 32);
static_assert(offsetof(sdfstream::gpu_shared::ProbeVolume, rayRotationCol0) == 48);
static_assert(offsetof(sdfstream::gpu_shared::ProbeVolume, blend) == 96);
static_assert(offsetof(sdfstream::gpu_shared::ProbeVolume, visibility) == 112);
static_assert(sizeof(sdfstream::gpu_shared::ProbeUpdatePushConstants) == 64);
static_assert(sizeof(sdfstream::gpu_shared::ProbeQuery) == 48);
static_assert(sdfstream::gpu_shared::kProbeBlendTexelsPerProbe ==
              sdfstream::gpu_shared::kProbeIrradianceInterior *
                      sdfstream::gpu_shared::kProbeIrradianceInterior +
                  sdfstream::gpu_shared::kProbeDepthInterior *
                      sdfstream::gpu_shared::kProbeDepthInterior);
static_assert(sdfstream::gpu_shared::kProbeTileTexelsPerProbe ==
              sdfstream::gpu_shared::kProbeIrradianceTexels *
                      sdfstream::gpu_shared::kProbeIrradianceTexels +
                  sdfstream::gpu_shared::kProbeDepthTexels * sdfstream::gpu_shared::kProbeDepthTexels);
static_assert(sdfstream::gpu_shared::kProbeIrradianceInterior +
                  2 * sdfstream::gpu_shared::kProbeBorderTexels ==
              sdfstream::gpu_shared::kProbeIrradianceTexels);
static_assert(sdfstream::gpu_shared::kProbeDepthInterior +
                  2 * sdfstream::gpu_shared::kProbeBorderTexels ==
              sdfstream::gpu_shared::kProbeDepthTexels);
#endif

#endif
