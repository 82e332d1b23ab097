#include "gi/card_light_slots.h"

#include <algorithm>
#include <limits>

namespace sdfstream {

namespace gs = gpu_shared;

namespace {
constexpr std::int64_t kMovedBoost = 8;
// Blocks lit before the last light change go before every block lit since (their light is of the
// old lights), in the order of their age.
constexpr std::int64_t kLightsChangedBoost = std::int64_t(1) << 40;
constexpr std::uint32_t kLevels = gs::kCardLightLevels;

// The level for an instance `distance` from the viewer, keeping `current` (-1: none) while the
// distance stays within its band widened by an eighth of `beyond` on both sides.
std::uint32_t levelAt(float distance, float beyond, int current) {
  if (beyond <= 0.0f) return 0;
  const std::uint32_t wanted = distance > 2.0f * beyond ? 2u : distance > beyond ? 1u : 0u;
  if (current < 0 || std::uint32_t(current) == wanted) return wanted;
  const float margin = beyond / 8.0f;
  const float lo = float(current) * beyond - margin;  // level 0 has no lower edge
  const float hi = current + 1 < int(kLevels) ? float(current + 1) * beyond + margin
                                              : std::numeric_limits<float>::infinity();
  return (current == 0 || distance > lo) && distance < hi ? std::uint32_t(current) : wanted;
}
}  // namespace

CardLightSlots::Block* CardLightSlots::find(std::uint32_t id) {
  return id < blocks_.size() && blocks_[id].mesh != kNoBlock ? &blocks_[id] : nullptr;
}

CardLightSlots::Block& CardLightSlots::insert(std::uint32_t id, const Block& block) {
  if (id >= blocks_.size()) blocks_.resize(std::max<std::size_t>(id + 1, blocks_.size() * 3 / 2));
  Block& b = blocks_[id];
  b = block;
  b.liveIndex = std::uint32_t(live_.size());
  live_.push_back(id);
  return b;
}

void CardLightSlots::release(std::uint32_t id) {
  const Block& block = blocks_[id];
  free_[block.mesh * kLevels + block.level].push_back(block.base);
  const std::uint32_t at = block.liveIndex;
  blocks_[live_.back()].liveIndex = at;
  live_[at] = live_.back();
  live_.pop_back();
  blocks_[id].mesh = kNoBlock;
}

std::vector<std::uint32_t> CardLightSlots::assign(std::span<gs::ObjectInstanceGpu> instances,
                                                  std::span<const std::uint32_t> meshTexels,
                                                  bool relightAll, std::uint32_t budget,
                                                  std::uint64_t capacityTexels, glm::vec3 viewer,
                                                  std::uint64_t texelBudget,
                                                  const CardLightLevels& levels) {
  ++frame_;
  stats_ = {};
  if (free_.size() < meshTexels.size() * kLevels) free_.resize(meshTexels.size() * kLevels);
  const bool byDistance =
      levels.beyond > 0.0f && levels.texels.size() >= meshTexels.size() * kLevels;
  if (relightAll) lightsFrame_ = frame_;
  // Keys, smaller first: never lit, then lit before the last light change (oldest first), then
  // the frame of the last relight, a moved instance counting kMovedBoost frames older (so moves
  // go first, yet when everything moves every instance still takes its turn: the oldest first).
  // Resetting every block to "never lit" on a light change instead would, with lights that change
  // every frame, relight the same lowest indices every frame and starve the rest.
  const bool overCap = [&] {
    std::uint64_t wanted = 0;  // at level 0: a cap that level 0 fits needs no distances
    for (const gs::ObjectInstanceGpu& inst : instances)
      wanted += inst.info.x < meshTexels.size() ? meshTexels[inst.info.x] : 0u;
    return wanted > capacityTexels;
  }();
  std::vector<float>& distance = distance_;
  if (byDistance || overCap) {
    distance.resize(instances.size());
    for (std::uint32_t i = 0; i < instances.size(); ++i) {
      const glm::vec3 lo(instances[i].boundsMin), hi(instances[i].boundsMax);
      distance[i] = glm::length(glm::max(glm::max(lo - viewer, viewer - hi), glm::vec3(0.0f)));
    }
  }
  // Blocks of instances gone this frame (or now showing another mesh) go back to their mesh's
  // free list first, so this frame's newcomers can take them; so do blocks of another level than
  // the instance's now (a new block of the right size is handed out below and relit first, as
  // never lit). One lookup per instance here.
  std::vector<std::uint32_t>& level = level_;
  level.assign(instances.size(), 0u);
  for (std::uint32_t i = 0; i < instances.size(); ++i) {
    const gs::ObjectInstanceGpu& inst = instances[i];
    Block* block = find(inst.info.z);
    const bool sameMesh = block && block->mesh == inst.info.x;
    if (sameMesh) block->seenFrame = frame_;
    if (!byDistance) continue;
    const int current = sameMesh ? int(block->level) : -1;
    level[i] = levelAt(distance[i], levels.beyond, current);
    if (current >= 0 && std::uint32_t(current) != level[i]) {
      release(inst.info.z);
      ++stats_.relevelled;
    }
  }
  for (std::size_t k = 0; k < live_.size();) {
    const std::uint32_t id = live_[k];
    if (blocks_[id].seenFrame != frame_) {
      release(id);  // the last live id moves to k: look at k again
    } else {
      ++k;
    }
  }
  auto texelsOf = [&](std::uint32_t i) -> std::uint32_t {
    const std::uint32_t mesh = instances[i].info.x;
    if (mesh >= meshTexels.size() || meshTexels[mesh] == 0) return 0u;
    return byDistance ? levels.texels[mesh * kLevels + level[i]] : meshTexels[mesh];
  };
  // Over the cap: keep the nearest instances whose blocks fit, hand out blocks nearest first,
  // and evict the rest (their blocks return to the free lists before anyone allocates).
  std::uint64_t wanted = 0;
  for (std::uint32_t i = 0; i < instances.size(); ++i) wanted += texelsOf(i);
  std::vector<std::uint32_t>& order = order_;
  order.resize(instances.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::vector<std::uint8_t>& kept = kept_;
  kept.assign(instances.size(), 1u);
  if (wanted > capacityTexels) {
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return distance[a] < distance[b]; });
    std::uint64_t sum = 0;
    for (std::uint32_t i : order) {
      sum += texelsOf(i);
      kept[i] = sum <= capacityTexels;
    }
    for (std::uint32_t i = 0; i < instances.size(); ++i) {
      if (kept[i]) continue;
      if (!find(instances[i].info.z)) continue;
      release(instances[i].info.z);
      ++stats_.evicted;
    }
  }
  std::vector<Candidate>& candidates = candidates_;
  candidates.clear();
  for (std::uint32_t i : order) {
    gs::ObjectInstanceGpu& inst = instances[i];
    inst.info.w = gs::kNoCardLight;
    const std::uint32_t mesh = inst.info.x;
    const std::uint32_t texels = texelsOf(i);
    if (texels == 0) continue;
    if (!kept[i]) {
      ++stats_.overBudget;
      continue;
    }
    Block* found = find(inst.info.z);
    if (!found) {
      Block block;
      block.mesh = mesh;
      block.level = level[i];
      block.seenFrame = frame_;
      std::vector<std::uint32_t>& freed = free_[mesh * kLevels + block.level];
      if (!freed.empty()) {
        block.base = freed.back();
        freed.pop_back();
      } else if (end_ + texels <= capacityTexels && end_ + texels <= gs::kCardLightBaseMask) {
        block.base = std::uint32_t(end_);
        end_ += texels;
      } else {
        ++stats_.overBudget;
        continue;
      }
      found = &insert(inst.info.z, block);
    }
    const Block& block = *found;
    inst.info.w = block.base | block.level << gs::kCardLightLevelShift;
    ++stats_.withCards;
    ++stats_.atLevel[block.level];
    stats_.liveTexels += texels;
    const bool moved = (inst.info.y & gs::kObjectFlagMoved) != 0u;
    std::int64_t key = std::int64_t(block.litFrame) - (moved ? kMovedBoost : 0);
    if (block.litFrame < lightsFrame_) key -= kLightsChangedBoost;
    if (block.litFrame == 0) key = std::numeric_limits<std::int64_t>::min();
    candidates.push_back({key, i});
  }
  const std::size_t take = std::min<std::size_t>(budget, candidates.size());
  auto byKey = [](const Candidate& a, const Candidate& b) {
    return a.key != b.key ? a.key < b.key : a.index < b.index;
  };
  if (take < candidates.size())
    std::nth_element(candidates.begin(), candidates.begin() + take, candidates.end(), byKey);
  // The texel budget cuts the first `take` in key order (sorting only those).
  std::sort(candidates.begin(), candidates.begin() + std::ptrdiff_t(take), byKey);
  std::vector<std::uint32_t> relight;
  relight.reserve(take);
  for (std::size_t k = 0; k < take; ++k) {
    const std::uint64_t texels = texelsOf(candidates[k].index);
    if (!relight.empty() && stats_.relitTexels + texels > texelBudget) break;
    relight.push_back(candidates[k].index);
    stats_.relitTexels += texels;
  }
  std::sort(relight.begin(), relight.end());
  for (std::uint32_t i : relight) blocks_[instances[i].info.z].litFrame = frame_;
  for (const Candidate& c : candidates) {
    const std::uint64_t lit = blocks_[instances[c.index].info.z].litFrame;
    stats_.maxStaleFrames = std::max(stats_.maxStaleFrames, lit == 0 ? frame_ : frame_ - lit);
  }
  stats_.relit = std::uint32_t(relight.size());
  return relight;
}

}  // namespace sdfstream
