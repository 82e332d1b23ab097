// Where each instance's card light lives and which instances are relit this frame (host side of
// the card light, shaders/card_light.comp). An instance's light takes one texel per card texel
// of its mesh, in one block at ObjectInstanceGpu::info.w. Blocks are kept per instance id across
// frames (the light persists and is only relit within a budget), and freed blocks go to a free
// list per mesh: a later instance of the same mesh takes one back whole, so the same churn of
// meshes never grows the atlas (no fragmentation drift), and the high-water mark is bounded by
// the most instances of each mesh alive at once.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "shaders/shared/card_layout.h"
#include "shaders/shared/object_layout.h"

namespace sdfstream {

// Card resolution by distance: an instance's light is kept at a coarser level (card_layout.h, one
// light texel per 2^l x 2^l card texels) the farther it is from the viewer, as the cascades that
// see it resolve 2^c voxels.
struct CardLightLevels {
  // Light texels of mesh m at level l: texels[m * kCardLightLevels + l] (empty: level 0 only).
  std::span<const std::uint32_t> texels;
  // Distance (stack space, to the instance's AABB) beyond which level 1 is used, and beyond twice
  // it level 2; 0: always level 0. An instance keeps its level until it is beyond the band's edge
  // by an eighth of this, so one on a boundary does not flip (and relight) every frame.
  float beyond = 0.0f;
};

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
    std::uint32_t relevelled = 0;      // instances whose level changed (a new block, relit first)
    std::array<std::uint32_t, gpu_shared::kCardLightLevels> atLevel{};  // with cards, per level
  };

  // For this frame's instances (dense, info.x = mesh, info.y = kObjectFlag* bits, info.z = id,
  // each id at most once, as InstanceSet's: the per-instance passes run in parallel):
  // sets info.w (block base | level << kCardLightLevelShift, or kNoCardLight when the mesh has
  // no cards or the cap of
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
  // in which blocks are handed out then. `levels` sizes blocks by distance (the texel counts,
  // caps and budgets above are then of the instance's level); a level change is a new block.
  std::vector<std::uint32_t> assign(std::span<gpu_shared::ObjectInstanceGpu> instances,
                                    std::span<const std::uint32_t> meshTexels, bool relightAll,
                                    std::uint32_t budget, std::uint64_t capacityTexels,
                                    glm::vec3 viewer = glm::vec3(0.0f),
                                    std::uint64_t texelBudget = ~std::uint64_t(0),
                                    const CardLightLevels& levels = {});

  // Texels the atlas must hold: every block ever handed out (the high-water mark).
  std::uint64_t endTexel() const { return end_; }
  const Stats& stats() const { return stats_; }

 private:
  struct Block {
    std::uint32_t mesh = kNoBlock;  // kNoBlock: the id holds no block
    std::uint32_t level = 0;
    std::uint32_t base = 0;
    std::uint32_t liveIndex = 0;  // its place in live_
    std::uint64_t litFrame = 0;   // 0: never lit
    std::uint64_t seenFrame = 0;
  };
  static constexpr std::uint32_t kNoBlock = ~0u;
  // By instance id, dense: InstanceSet issues ids from 0 and never reuses them, so this costs
  // 32 bytes per id ever issued and no hashing (a hash map here was ~9 ms a frame at 100,000
  // instances). live_ lists the ids holding a block, so finding the blocks of instances gone
  // this frame costs the live blocks, not every id ever seen.
  std::vector<Block> blocks_;
  std::vector<std::uint32_t> live_;
  Block* find(std::uint32_t id);
  Block& insert(std::uint32_t id, const Block& block);
  // The id's block goes back to its (mesh, level) free list and the id holds none.
  void release(std::uint32_t id);
  // Per mesh and level (mesh * kCardLightLevels + level): bases of freed blocks.
  std::vector<std::vector<std::uint32_t>> free_;
  // Per-frame scratch, kept so that its capacity is reused (at 100,000 instances fresh vectors
  // were megabytes of new pages every frame).
  struct Candidate {
    std::int64_t key;
    std::uint32_t index;
  };
  std::vector<float> distance_;
  std::vector<std::uint32_t> level_, order_;
  std::vector<std::uint8_t> kept_, flag_;
  std::vector<std::int64_t> key_;
  std::vector<Candidate> candidates_;
  std::vector<std::vector<Candidate>> chunkCandidates_;  // per chunk of instances
  std::uint64_t end_ = 0;
  std::uint64_t frame_ = 0;
  std::uint64_t lightsFrame_ = 0;  // the frame of the last light change
  Stats stats_;
};

}  // namespace sdfstream
