// The brick, page-table and ray/hit formats shared by the importer, the cascade builder, the
// CPU reference tracer and the trace shader. One definition (STYLE.md habit 1); sizes are
// static_asserted below and checked against the shader's view by tests.
//
// Coordinate spaces
//  - World index space: voxel (i,j,k) is the sample at world position worldOrigin + voxelSize*(i,j,k)
//    (OpenVDB's convention: samples sit at integer index coordinates).
//  - Brick b covers index cells [8b, 8b+8) on each axis. It stores 9 samples per axis
//    (8b .. 8b+8): the extra "apron" sample lets trilinear interpolation inside the brick
//    read only that brick (ARCHITECTURE.md, "Brick: 8³ distance samples plus an apron").
//  - Cascade space: a cascade is 128³ cells = 16³ pages of one brick each. Positions handed to
//    the GPU are floats in cascade voxel units relative to the cascade's minimum corner, so the
//    GPU never sees large world coordinates.
#ifndef SDFSTREAM_SDF_LAYOUT_H
#define SDFSTREAM_SDF_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"

SDF_BEGIN_NAMESPACE

SDF_CONST uint kBrickCells = 8;             // cells per brick edge
SDF_CONST uint kBrickSamples = 9;           // samples per brick edge (cells + apron)
SDF_CONST uint kBrickSampleCount = 729;     // 9³ distance samples
SDF_CONST uint kBrickDistanceWords = 365;   // 729 fp16 values packed two per uint (last half unused)
SDF_CONST uint kBrickMaterialCount = 512;   // 8³ material voxels, one per cell (cell-centred)
// Cell corners: the same fp16 distances regrouped per trilinear cell, so a sample of the trace
// reads one uvec4 (the 8 corners of its cell) instead of 8 scattered words. Cell x + 8(y + 8z)
// holds (d000, d100), (d010, d110), (d001, d101), (d011, d111), low half first (dXYZ = the
// sample at cell + (X, Y, Z)). Built on the GPU from the distance atlas (brick_corners.comp);
// the values are bit for bit those of the distance atlas, so traces are unchanged.
SDF_CONST uint kBrickCornerWords = 2048;  // 512 cells × 4 words

// Distances are stored in voxel units (distance / voxelSize), fp16, clamped to +-kNarrowBand.
// Three voxels is OpenVDB's default half-width (LEVEL_SET_HALF_WIDTH) and enough for the
// sign and gradient of a sphere trace; farther space is handled by page bounds.
SDF_CONST float kNarrowBand = 3.0;

SDF_CONST uint kCascadeCells = 128;         // cells per cascade edge
SDF_CONST uint kCascadePages = 16;          // pages (brick slots) per cascade edge
SDF_CONST uint kCascadePageCount = 4096;    // 16³

// Page-table entry encoding (one uint per page):
//  - bit 31 set: resident brick; bits 0..30 = atlas slot index.
//  - bit 31 clear: no brick; bits 0..30 = conservative distance bound to the nearest surface,
//    in whole voxels, from any point of this page (0 = only "no surface inside this page").
//  - payload kPageMissing (bit 31 clear): the page is needed but its data is not resident yet
//    (streaming never waits for it); traversal must fall back to a coarser cascade there.
SDF_CONST uint kPageResidentBit = 0x80000000u;
SDF_CONST uint kPagePayloadMask = 0x7fffffffu;
SDF_CONST uint kPageMissing = 0x7fffffffu;

// One ray for the trace pass, in cascade voxel units (see above).
struct TraceRay {
  vec4 originTMin;  // xyz origin, w = tMin           (bytes 0..15)
  vec4 dirTMax;     // xyz unit direction, w = tMax   (bytes 16..31)
};

// The trace pass's result for one ray. t < 0 means miss.
struct TraceHit {
  vec4 normalT;     // xyz = unit SDF gradient at the hit, w = hit distance t (or -1)  (0..15)
  uint albedo;      // RGBA8 (sRGB-encoded base colour) of the hit cell                (16..19)
  uint emission;    // RGB9E5 linear emission of the hit cell                          (20..23)
  uint steps;       // sphere-tracing iterations spent (for cost metrics)              (24..27)
  uint flags;       // kHitFlag* bits                                                  (28..31)
};

SDF_CONST uint kHitFlagHit = 1u;
SDF_CONST uint kHitFlagRanOutOfSteps = 2u;
SDF_CONST uint kHitFlagMissingData = 4u;  // stopped at a page not streamed in yet
SDF_CONST uint kHitFlagFellBack = 8u;     // a missing page sent the ray to a coarser cascade
SDF_CONST uint kHitCascadeShift = 8u;     // flags >> 8 & 15: cascade of the hit (stack traversal)

// Push constants of trace_rays.comp.
struct TracePushConstants {
  uvec4 toroidalOffset;  // xyz = cascade origin brick mod 16 (page-table scroll), w unused (0..15)
  uint rayCount;         //                                                       (16..19)
  uint maxSteps;         // sphere-tracing iteration cap                          (20..23)
  float hitEpsilon;      // in voxels: a sample below this is a hit               (24..27)
  uint pad0;             //                                                       (28..31)
};

// One cascade of the stack as the multi-cascade traversal sees it (sdfTraceStack).
struct CascadeTraceParams {
  vec4 offsetScale;  // xyz: this cascade's min corner in cascade-0 voxels relative to cascade 0's
                     // min corner; w: its voxel size in cascade-0 voxels (2^c)      (0..15)
  uvec4 toroidal;    // xyz: origin brick mod 16; w: first page-table entry (c * 4096) (16..31)
};

// Push constants of trace_stack.comp.
struct TraceStackPushConstants {
  uint rayCount;
  uint maxSteps;
  float hitEpsilon;
  uint cascadeCount;
  uint firstCascade;  // rays start in this cascade and go coarser (a probe of that cascade)
  uint cellCorners;   // 1: the atlas binding holds the corner atlas (kBrickCornerWords), 0: the
                      // distance atlas
};

// Push constants of brick_corners.comp.
struct BrickCornersPush {
  uint slotCount;  // slots to regroup
  uint listed;     // 1: the k-th slot is the slot list's entry k; 0: slot k itself
  uint pad0;
  uint pad1;
};

SDF_CONST uint kMaxCascades = 8;

SDF_END_NAMESPACE

#ifdef __cplusplus
static_assert(sizeof(sdfstream::gpu_shared::CascadeTraceParams) == 32);
static_assert(sizeof(sdfstream::gpu_shared::TraceStackPushConstants) == 24);
static_assert(sizeof(sdfstream::gpu_shared::TraceRay) == 32);
static_assert(sizeof(sdfstream::gpu_shared::TraceHit) == 32);
static_assert(sizeof(sdfstream::gpu_shared::TracePushConstants) == 32);
static_assert(sizeof(sdfstream::gpu_shared::BrickCornersPush) == 16);
static_assert(sdfstream::gpu_shared::kBrickCornerWords ==
              4 * sdfstream::gpu_shared::kBrickMaterialCount);
static_assert(sdfstream::gpu_shared::kBrickSamples * sdfstream::gpu_shared::kBrickSamples *
                  sdfstream::gpu_shared::kBrickSamples ==
              sdfstream::gpu_shared::kBrickSampleCount);
static_assert((sdfstream::gpu_shared::kBrickSampleCount + 1) / 2 ==
              sdfstream::gpu_shared::kBrickDistanceWords);
static_assert(sdfstream::gpu_shared::kCascadePages * sdfstream::gpu_shared::kBrickCells ==
              sdfstream::gpu_shared::kCascadeCells);
#endif

#endif
