// Where each instance's card light lives and which instances are relit this frame (host side of
// the card light, shaders/card_light.comp). An instance's light takes one texel per card texel
// of its mesh, in one block at ObjectInstanceGpu::info.w. Blocks are kept per instance id across
// frames (the light persists and is only relit within a budget), and freed blocks go to a free
// list per mesh: a later instance of the same mesh takes one back whole, so the same churn of
// meshes never grows the atlas (no fragmentation drift), and the high-water mark is bounded by
// the most instances of each mesh alive at once.
#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "shaders/shared/object_layout.h"

namespace sdfstream {

class CardLightSlots {
 public:
  struct Stats {
    std::uint32_t relit = 0;           // instances in this frame's relight list
    std::uint64_t relitTexels = 0;     // their card texels
    std::uint32_t withCards = 0;       // instances with a light block
    std::uint32_t overBudget = 0;      // instances left without cards by the memory cap
    std::uint32_t evicted = 0;         // blocks taken from instances farther than the kept ones
    std::uint64_t maxStaleFrames = 0;  // frames since the longest-unlit instance's last relight
    std::uint64_t liveTexels = 0;      // texels of the blocks in use
  };

  // For this frame's instances (dense, info.x = mesh, info.y = kObjectFlag* bits, info.z = id):
  // sets info.w (block base, or kNoCardLight when the mesh has no cards or the cap of
  // capacityTexels is reached), frees the blocks of ids not present, and returns the indices (into
  // `instances`) to relight, at most `budget` instances and `texelBudget` texels (but at least one
  // instance: a mesh larger than the texel budget still gets relit, alone): never lit first, then
  // the longest unlit, a moved instance counting 8 frames staler (moves first, but no instance
  // starves when all move). The texel budget bounds the pass's time, which grows with texels (a
  // shadow ray each), not instances: 256 instances of 128² cards would be 25 M texels.
  // relightAll (the lights changed) puts every block lit before the change ahead of those lit
  // since, oldest first among them, so lights that change every frame (a moving sun) still relight
  // every instance in turn. meshTexels[m]: texels of mesh m's cards (0: none).
  // When the instances want more than capacityTexels, the nearest to `viewer` (stack space; the
  // distance to their AABB) keep or get cards and the farther ones are evicted: their blocks go
  // back to the free lists for nearer instances of the same mesh. Nearer first is also the order
  // in which blocks are handed out then.
  std::vector<std::uint32_t> assign(std::span<gpu_shared::ObjectInstanceGpu> instances,
                                    std::span<const std::uint32_t> meshTexels, bool relightAll,
                                    std::uint32_t budget, std::uint64_t capacityTexels,
                                    glm::vec3 viewer = glm::vec3(0.0f),
                                    std::uint64_t texelBudget = ~std::uint64_t(0));

  // Texels the atlas must hold: every block ever handed out (the high-water mark).
  std::uint64_t endTexel() const { return end_; }
  const Stats& stats() const { return stats_; }

 private:
  struct Block {
    std::uint32_t mesh = 0;
    std::uint32_t base = 0;
    std::uint64_t litFrame = 0;  // 0: never lit
    std::uint64_t seenFrame = 0;
  };
  std::unordered_map<std::uint32_t, Block> blocks_;  // by instance id
  std::vector<std::vector<std::uint32_t>> free_;     // per mesh: bases of freed blocks
  std::uint64_t end_ = 0;
  std::uint64_t frame_ = 0;
  std::uint64_t lightsFrame_ = 0;  // the frame of the last light change
  Stats stats_;
};

}  // namespace sdfstream
