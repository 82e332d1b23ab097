// The host half of the moving-object data: the object-SDF atlas from the library and,
// each frame, the instances carried into stack space plus the initial region records. Both the
// GPU ObjectScene and its CPU reference ObjectSceneCpu consume exactly these, so host math is
// written once.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "cards/card_layout.h"
#include "objects/instance_set.h"
#include "objects/object_library.h"
#include "shaders/shared/object_layout.h"
#include "streaming/cascade_stack.h"

namespace sdfstream {

struct ObjectSceneSettings {
  std::uint32_t regionCascades = 4;  // cascades with macro regions (<= kMaxRegionCascades)
  // Objects whose bounding radius is below this many voxels of cascade c > 0 are not listed there
  // (too small to block a coarse probe's rays; ARCHITECTURE: "object-size-to-voxel rule").
  float sizeRule = 0.5f;
  float hitEpsilon = 0.05f;     // grid voxels: a sample below this is a hit
  std::uint32_t maxSteps = 96;  // sphere-tracing steps per instance segment
  // A move wakes the probes whose irradiance it can change by at least this fraction (M21
  // Sec. 5, vigilant probes near dynamic changes). An object of bounding radius r seen from a
  // probe at distance d covers at most (r/d)^2 of its cosine-weighted hemisphere, so only probes
  // within r / sqrt(wakeIrradianceChange) of the changed box's centre (a ball, which holds the
  // box: r is its half-diagonal) wake, and only in the cascades whose probes see the object
  // (sizeRule lists it there). The default is the probe field's sleep threshold: a change below it
  // would not keep a probe awake either. 1 wakes only probes within the box's circumscribed ball;
  // clamped to [1e-4, 1].
  float wakeIrradianceChange = 0.05f;
  // Sub-cell headers (and as many sub-cell entries) a frame may hold, uvec4 each: memory for the
  // lists a ray reads per sub-cell it crosses (object_layout.h). Regions whose lists do not fit
  // are walked with their region list alone (correct, slower).
  std::uint32_t maxSubListEntries = 1u << 20;
  // Sub-cell lists are built only when the region lists are long: at least this many entries
  // per occupied region on average (Σ instances' region ranges / regions some range touches).
  // Shorter lists cost a ray a few box tests anyway, less than the two passes that build
  // sub-cell lists cost the frame (docs/DECISIONS.md, "Sub-cell lists only where region lists
  // are long"); without them every region is walked with its region list (kNoSubLists) and
  // those passes are not recorded. 0: always built.
  float subListMinMeanEntries = 8.0f;
  // Probe rays test every instance instead of walking the regions: the naive peer of the stress
  // benchmark (the regions are still built, so their cost is measured either way).
  bool naiveTraversal = false;
  // Cards (cards/, GS slides b "Storing lighting information"): each mesh's six views captured
  // once, each instance's direct light per card texel relit within a per-frame budget, read by
  // probe rays that hit the instance. Off: object hits take emission + the probes' light only.
  bool cards = true;
  CardSettings cardLayout;
  // World units per card texel (the slides' one texel per voxel of the finest cascade): 0 takes
  // the cascade-0 voxel of the first frame that sees the meshes, which then captures them (one
  // GPU submission); > 0 lets GiSystem::setObjects capture at once (an engine recording its own
  // frames then sees no submission by sdfstream in them). Never finer than the object's SDF.
  double cardTexelWorld = 0.0;
  // Instances whose card light is recomputed per frame at most: moved or never lit first, then
  // the longest unlit (so with N instances nothing is staler than N / budget frames).
  std::uint32_t cardRelightBudget = 256;
  // Card texels relit per frame at most (the pass's cost is a shadow ray per texel; at least one
  // instance is relit per frame whatever its size). 131072 keeps the stress world's 256 small
  // instances whole and spreads a few large objects' 98k-texel cards over frames.
  std::uint64_t cardRelightTexelBudget = 131072;
  // Card light memory cap (4 bytes per texel). When the instances want more, the nearest to the
  // camera (cascade 0's centre) keep cards and the farther ones are evicted (CardLightSlots).
  std::uint64_t cardLightBudgetBytes = 256ull << 20;
  // Card resolution by distance: instances beyond this many times cascade 0's half extent from
  // its centre keep their light at a quarter of the texels, beyond twice that at a sixteenth
  // (CardLightLevels). 0: every instance at full resolution.
  float cardLevelDistance = 1.0f;
};

// Every mesh of the library, packed: ObjectMeshGpu records, distances, (albedo, emission) pairs.
struct ObjectAtlasData {
  std::vector<gpu_shared::ObjectMeshGpu> meshes;
  std::vector<float> distance;
  std::vector<glm::uvec2> material;
};
ObjectAtlasData buildObjectAtlas(const ObjectLibrary& library);

struct ObjectFrameData {
  gpu_shared::ObjectFrameGpu frame{};
  std::vector<gpu_shared::ObjectInstanceGpu> instances;  // dense, InstanceSet order
  // count/cursor/occupancy 0; wake and moved from changedBoxes; without sub-cell lists also
  // start, slots and subBase (kNoSubLists), from the AABB ranges.
  std::vector<gpu_shared::ObjectRegionGpu> regions;
  std::uint32_t listCapacity = 0;  // Σ instances' AABB region ranges: lists can never overflow
                                   // (with slack when the GPU's scan places them)
  // Sub-cell headers, and as many sub-cell entries: Σ instances' AABB sub-cell volumes (at most
  // kSubListMaxCells a region), at most ObjectSceneSettings::maxSubListEntries; regions whose
  // sub-cell lists do not fit are walked without them (object_layout.h, kNoSubLists). 0: no
  // sub-cell lists this frame (short region lists, ObjectSceneSettings::subListMinMeanEntries).
  std::uint32_t subListCapacity = 0;
  std::uint32_t cascadeMask = 0;   // bit c: some instance is listed in cascade c (AABB level)
  std::uint32_t occupiedRegions = 0;  // regions some instance's AABB range touches
  std::uint32_t movedInstances = 0;
  std::uint32_t movedRegions = 0;  // regions with a wake bit (removals included)
  // InstanceSet::changedBounds of the frame (world space; each changed instance's start and end
  // boxes as one): the light cache relights the pages they shadow, and probes near them wake.
  std::vector<WorldBox> changedBoxes;
  // Scratch: per changed box and region cascade, its wake ball in cascade sub-cell coordinates
  // (0..64 across the cascade) and the sub-cell range its bounding cube covers (0..63, lo.x >
  // hi.x when it misses the cascade). Kept to reuse its capacity.
  struct SubCellRange {
    glm::ivec3 lo, hi;
    glm::vec3 centre{0.0f};
    float radius = 0.0f;
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  };
  std::vector<SubCellRange> wakeRanges;
  // CPU time of the build's parts (milliseconds; the frame's host-time breakdown). The two run
  // side by side: each is its own wall time, and the build takes about the longer, not the sum.
  double instancesMs = 0.0;  // the instances into stack space and what the frame sums over them
  double wakeMs = 0.0;       // changedBoxes and the wake bits
};

// The instance as the GPU sees it: grid <-> stack maps, stack AABB, step scale, radius.
gpu_shared::ObjectInstanceGpu instanceInStack(const ObjectSdf& mesh, std::uint32_t meshIndex,
                                              const glm::dmat4& worldFromObject,
                                              const CascadeStackImage& stack);

// Host work is parallel over instances and changed boxes (TBB). The out-parameter form reuses
// `out`'s buffers from frame to frame. changedBoxesReady, when set, is called (on some thread)
// as soon as out.changedBoxes holds this frame's boxes, while the rest is still being built:
// work that needs only those boxes can start then; out.changedBoxes does not change after it.
void buildObjectFrame(const ObjectLibrary& library, const InstanceSet& instances,
                      const CascadeStackImage& stack, const ObjectSceneSettings& settings,
                      ObjectFrameData& out, const std::function<void()>& changedBoxesReady = {});
ObjectFrameData buildObjectFrame(const ObjectLibrary& library, const InstanceSet& instances,
                                 const CascadeStackImage& stack,
                                 const ObjectSceneSettings& settings);

}  // namespace sdfstream
