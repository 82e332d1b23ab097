// Moving objects on the GPU (Godot SDFGI slides b, "Dynamic Objects"): the object-SDF
// atlas, the instances and the macro-region object lists, shared by the region build passes
// (object_regions.comp), the dynamic traversal (shaders/object_trace.glsl) and their C++
// references (gi/object_scene_cpu.cpp). One definition; sizes static_asserted below.
//
// Spaces
//  - Object space: the mesh's own coordinates (metres of the source file).
//  - Grid space: sample (i,j,k) of an object's dense SDF grid sits at object-space position
//    gridMin + voxel·(i,j,k). Distances are stored in grid voxels (distance / voxel).
//  - Stack space: cascade-0 voxels relative to cascade 0's minimum corner, as every ray of the
//    stack traversal (sdf_layout.h, CascadeTraceParams). Instance transforms are uploaded in
//    this space each frame, so the GPU never sees world coordinates.
//
// Macro regions: each of the first regionCascades cascades is split into 8³ regions of 16³ of
// its cells, measured from the cascade's current minimum corner. The lists are rebuilt from the
// instances every frame, so they scroll with the cascade for free.
#ifndef SDFSTREAM_OBJECT_LAYOUT_H
#define SDFSTREAM_OBJECT_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"

SDF_BEGIN_NAMESPACE

SDF_CONST uint kRegionCells = 16;         // cascade cells per macro-region edge
SDF_CONST uint kRegionsPerAxis = 8;       // 8 × 16 = 128 = kCascadeCells
SDF_CONST uint kRegionsPerCascade = 512;  // 8³
SDF_CONST uint kMaxRegionCascades = 4;    // cascades that may hold object lists
// Occupancy: each region is split into 8³ sub-cells of 2³ cells (GS slides b, "Split into
// smaller SDFs and combine with DDA": a bitfield "for looking up empty cells beforehand"); bit
// x + 8y + 64z of a region's 512 says some listed instance's AABB touches sub-cell (x, y, z).
SDF_CONST uint kSubCellsPerAxis = 8;
SDF_CONST uint kOccupancyWords = 16;  // 512 bits

// One mesh's local SDF in the atlas (ObjectMeta::meshes).
struct ObjectMeshGpu {
  uvec4 dimsOffset;  // xyz: samples per axis (>= 2); w: first sample in OBJ_SAMPLE's array
  vec4 gridMin;      // xyz: object-space position of sample (0,0,0); w: voxel edge (object units)
};

// One instance (OBJ_INSTANCE). Affine maps as three rows (row · (p, 1)).
struct ObjectInstanceGpu {
  vec4 gridFromStack[3];  // stack position -> grid coordinates (samples) of its mesh
  vec4 stackFromGrid[3];  // the inverse (hit positions and normals back to stack space)
  vec4 boundsMin;         // xyz: stack-space AABB of the mesh's grid box; w: stepScale, a lower
                          // bound of stack voxels per grid voxel along any direction (smallest
                          // singular value of stackFromGrid's 3×3), so grid distance × stepScale
                          // never overshoots the surface in stack space
  vec4 boundsMax;         // xyz: AABB max; w: bounding radius in stack voxels (size rule)
  uvec4 info;             // x: mesh index; y: kObjectFlag* bits; z: the user's object id;
                          // w: first texel of this instance's card light (OBJ_CARD_LIGHT) in
                          // bits 0-29, its light level (card_layout.h) in bits 30-31; or
                          // kNoCardLight (no cards: shaded from material and probes alone)
};

SDF_CONST uint kNoCardLight = 0xffffffffu;
SDF_CONST uint kCardLightBaseMask = 0x3fffffffu;  // info.w & mask: the light block's first texel
SDF_CONST uint kCardLightLevelShift = 30u;        // info.w >> shift: its level (0..2)

SDF_CONST uint kObjectFlagMoved = 1u;  // transform changed (or added/removed) this frame

// Sub-cell lists: an instance whose AABB touches at most kSubListMaxCells sub-cells of a region
// is also listed once per sub-cell it touches, so a ray tests only the objects of the occupied
// sub-cells it crosses. Larger ones ("wide") are tested once per region instead (their copies
// would grow with their volume). A region's occupied sub-cell k (k = rank of its bit among the
// region's occupancy bits) has a header uvec4 at OBJ_LIST(subBase + k): x first entry in OBJ_LIST,
// y entries, z fill cursor, w 0; the entries are objListEntry records of the region.
SDF_CONST uint kSubListMaxCells = 64;
SDF_CONST uint kNoSubLists = 0xffffffffu;  // subBase when the lists did not fit: walk the region
// object_regions_scan.comp's one workgroup: 4 regions a thread at kMaxRegionCascades (every
// desktop driver and lavapipe allow 1,024 invocations; ComputePipeline checks the limit).
SDF_CONST uint kRegionScanThreads = 512;
// ObjectRegionGpu in 16-byte words: the scan reads and writes a region's first 32 bytes (count ..
// wideCursor) as two of them.
SDF_CONST uint kRegionVec4s = 13;

// Per region and cascade (OBJ_REGION(c * 512 + r)).
struct ObjectRegionGpu {
  // What the walk reads first, in one 32-byte sector.
  uint count;    // instances listed: the `wide` ones first, then the rest
  uint start;    // first entry in OBJ_LIST (uvec4 each: objListEntry)
  uint wide;     // listed instances touching more than kSubListMaxCells sub-cells
  uint subBase;  // OBJ_LIST index of the first sub-cell header, or kNoSubLists (the rank pass
                 // leaves the region's occupied sub-cells here for the scan)
  // The box of the occupied sub-cells as masks of the occupied x, y and z (bits 0-7, 8-15,
  // 16-23; written by the rank pass or ORed in by the fill into host-placed lists; 0 when none).
  // A ray walks the sub-cells only where it crosses the box.
  uint occupiedBounds;
  uint subStart;    // count pass: sub-cell entries; after the scan: the first one's OBJ_LIST index
  uint cursor;      // fill pass scratch (entries after the wide ones)
  uint wideCursor;  // fill pass scratch
  // Sub-cells the AABBs of the listed instances that are not wide touch (bit above).
  uint occupancy[kOccupancyWords];
  // Sub-cells (same bits) within wake distance of an instance that moved, appeared or vanished
  // this frame (old and new poses; host-built, gi/object_frame.h): a probe there turns vigilant.
  uint wake[kOccupancyWords];
  // Occupied sub-cells before occupancy word w: bits 16 (w % 2) .. +15 of rank[w / 2].
  uint rank[kOccupancyWords / 2];
  uint moved;  // nonzero: some wake bit above is set
  // Without sub-cell lists, the list slots the host sized for the region (its instances' AABB
  // ranges; `start` is host-written too): no count, rank or scan pass runs, the fill appends
  // below it, `wide` and `rank` stay 0. 0 when the passes size the lists.
  uint slots;
  uint pad1;
  uint pad2;
};

// Frame constants (ObjectMeta::frame, host-written each frame).
struct ObjectFrameGpu {
  uvec4 counts;  // x: instances; y: region cascades K (<= kMaxRegionCascades); z: region list
                 // capacity (entries); w: meshes
  vec4 regionOrigin[kMaxRegionCascades];  // xyz: cascade c's min corner in stack space;
                                          // w: its region edge in stack voxels (16 · 2^c)
  vec4 boundsMin;  // xyz: stack-space AABB of every instance (empty when none); w: 0
  vec4 boundsMax;  // rays search objects only where they cross it
  vec4 params;     // x: size rule, the smallest bounding radius in voxels of cascade c an object
                   // needs to be listed in c > 0 (0 lists every object everywhere); y: hit epsilon
                   // in grid voxels; z: max sphere-tracing steps per object segment; w: 0
};

// Push constants of object_regions.comp (every phase shares one layout). OBJ_LIST holds the
// region lists' `capacity` entries, then `subCapacity` sub-cell headers, then `subCapacity`
// sub-cell entries.
struct ObjectRegionPush {
  uint phase;  // 0 count, 1 rank, 2 scan, 3 sub-cell count, 4 sub-cell scan, 5 fill,
               // 6 fill into the host's slots (no sub-cell lists: the only pass)
  uint instances;
  uint cascades;
  uint capacity;
  uint subCapacity;
  uint pad0;
  uint pad1;
  uint pad2;
};

// One ray's result of object_trace.comp (tests and the stress benchmark).
struct ObjectTraceHit {
  vec4 normalT;  // xyz unit stack-space normal, w = t (< 0: no object hit)
  uint instance;
  uint albedo;
  uint emission;
  uint steps;       // sphere-tracing steps over every instance tried
  uint tried;       // instance segments traced
  uint cardLight;   // RGB9E5: the hit's light read from its instance's cards (card_lookup.glsl)
  uint cardWeight;  // float bits: the accepted cards' normal weight (0: no card saw the hit)
  uint cardTexel;   // the first accepted card texel's index (kNoCardLight: none)
};

struct ObjectTracePush {
  uint rayCount;
  uint mode;  // 0 region lists, 1 every instance (brute force)
  uint pad0;
  uint pad1;
};

SDF_END_NAMESPACE

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(sdfstream::gpu_shared::ObjectMeshGpu) == 32);
static_assert(sizeof(sdfstream::gpu_shared::ObjectInstanceGpu) == 144);
static_assert(sizeof(sdfstream::gpu_shared::ObjectRegionGpu) ==
              16 * sdfstream::gpu_shared::kRegionVec4s);
// object_regions_scan.comp reads and writes these two 16-byte words by position.
static_assert(offsetof(sdfstream::gpu_shared::ObjectRegionGpu, subBase) == 12 &&
              offsetof(sdfstream::gpu_shared::ObjectRegionGpu, occupiedBounds) == 16 &&
              offsetof(sdfstream::gpu_shared::ObjectRegionGpu, subStart) == 20 &&
              offsetof(sdfstream::gpu_shared::ObjectRegionGpu, wideCursor) == 28);
static_assert(sizeof(sdfstream::gpu_shared::ObjectFrameGpu) == 128);
static_assert(sizeof(sdfstream::gpu_shared::ObjectRegionPush) == 32);
static_assert(sizeof(sdfstream::gpu_shared::ObjectTraceHit) == 48);
static_assert(sizeof(sdfstream::gpu_shared::ObjectTracePush) == 16);
static_assert(sdfstream::gpu_shared::kRegionCells * sdfstream::gpu_shared::kRegionsPerAxis == 128);
#endif

#endif
