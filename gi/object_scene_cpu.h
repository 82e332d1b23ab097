// CPU reference of the moving-object passes: region lists by brute force
// (every region of every region cascade tested against every instance, no AABB ranges, no
// atomics) and the traversal of shaders/object_trace.glsl compiled as C++ (the same math as the
// GPU: STYLE.md habit 9).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gi/light_cache.h"
#include "gi/object_frame.h"
#include "shaders/shared/card_layout.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream {

// What objTraceRegions did for the rays it walked, summed (the GLSL's OBJ_COUNT points):
// region DDA steps, regions with a list, regions whose occupied sub-cells the ray crossed,
// occupancy DDA steps, occupied sub-cells whose list was read, list entries whose box was tested,
// and boxes the ray crossed (whose instance was then sphere traced).
struct ObjectWalkCounts {
  std::uint64_t rays = 0, regionSteps = 0, listedRegions = 0, occupiedRegions = 0,
                occupancySteps = 0, occupiedCells = 0, entriesTested = 0, boxesCrossed = 0;
};

class ObjectSceneCpu {
 public:
  ObjectSceneCpu(const ObjectLibrary& library, const InstanceSet& instances,
                 const CascadeStackImage& stack, const ObjectSceneSettings& settings = {});

  // Per region (cascade * 512 + region): the sorted instance indices whose OBB overlaps it
  // (size rule applied).
  const std::vector<std::vector<std::uint32_t>>& regionInstances() const { return lists_; }
  // The sorted instances listed for sub-cell `bit` (x + 8y + 64z) of a region: those of the
  // region's list that are not wide (ObjectRegionGpu::wide) and whose AABB touches it; empty
  // where the region has no sub-cell lists (kNoSubLists).
  std::vector<std::uint32_t> subCellInstances(std::uint32_t region, std::uint32_t bit) const;
  // objMovedNear of shaders/object_trace.glsl: whether a probe at stack point p of cascade c
  // wakes (the host's wake bits, copied from frame()).
  bool wakes(glm::vec3 stackPoint, std::uint32_t cascade) const;
  // Per region: the occupancy bitfield (object_layout.h) of its listed instances' AABBs, and
  // the frame's wake bits.
  const std::vector<gpu_shared::ObjectRegionGpu>& regions() const { return regions_; }

  // objTraceRegions / objTraceAll of shaders/object_trace.glsl, as C++.
  gpu_shared::ObjectTraceHit traceRegions(const gpu_shared::TraceRay& ray,
                                          ObjectWalkCounts* counts = nullptr) const;
  gpu_shared::ObjectTraceHit traceAll(const gpu_shared::TraceRay& ray) const;
  // objOccluded (shadow rays: the walk stops at the first hit found).
  bool occluded(const gpu_shared::TraceRay& ray) const;

  const ObjectFrameData& frame() const { return frame_; }

  // The cards the traces read their hits' light from (shaders/card_lookup.glsl): the card table
  // and texels (as ObjectScene::cardTable / cardTexels), the card light, and each instance's
  // light base (ObjectInstanceGpu::info.w, in frame() order). Without them hits carry no light.
  void setCards(std::vector<gpu_shared::CardGpu> table,
                std::vector<gpu_shared::CardTexelGpu> texels, std::vector<std::uint32_t> light,
                std::span<const std::uint32_t> instanceLightBases);

  // shaders/card_light.glsl as C++ (card_light.comp's loop for one instance): the light of every
  // light texel of instance i's six cards at its light level (info.w's top bits), in card order
  // (the block's layout from its base), RGB9E5 as the pass writes it, lit by `lights`
  // (cascade-0 voxels, toGpu) with shadows through `stack` and these objects. Needs setCards.
  std::vector<std::uint32_t> cardLight(std::uint32_t instance, const CascadeStackImage& stack,
                                       std::span<const gpu_shared::GpuLight> lights,
                                       const LightCacheSettings& settings = {}) const;

 private:
  ObjectAtlasData atlas_;
  ObjectFrameData frame_;
  std::vector<std::vector<std::uint32_t>> lists_;
  std::vector<gpu_shared::ObjectRegionGpu> regions_;  // count/start/subBase/subStart into flat_
  // OBJ_LIST: the region lists' entries (objListEntry; region after region, wide ones first),
  // every region's sub-cell headers, then the sub-cell entries.
  std::vector<glm::uvec4> flat_;
  std::vector<gpu_shared::CardGpu> cardTable_;
  std::vector<gpu_shared::CardTexelGpu> cardTexels_;
  std::vector<std::uint32_t> cardLight_;
};

}  // namespace sdfstream
