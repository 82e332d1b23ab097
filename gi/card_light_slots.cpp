#include "gi/card_light_slots.h"

#include <algorithm>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace sdfstream {

namespace gs = gpu_shared;

namespace {
constexpr std::int64_t kMovedBoost = 8;
// Blocks lit before the last light change go before every block lit since (their light is of the
// old lights), in the order of their age.
constexpr std::int64_t kLightsChangedBoost = std::int64_t(1) << 40;
constexpr std::uint32_t kLevels = gs::kCardLightLevels;
// Instances per parallel task in the per-instance passes below.
constexpr std::size_t kInstancesPerTask = 2048;

template <typename Sum, typename Body>
Sum parallelSum(std::size_t n, Body body) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kInstancesPerTask), Sum{},
      [&](const tbb::blocked_range<std::size_t>& range, Sum sum) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) sum += body(i);
        return sum;
      },
      [](Sum a, Sum b) { return a + b; });
}

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
  // The per-instance passes run in parallel and write only their instance's entries (and, for
  // the instance's id, its block: ids are distinct, as InstanceSet's are); whatever changes the
  // shared block lists or free lists is applied serially after, in instance order, so the
  // result does not depend on the threads.
  // Each instance's distance to the viewer (for levels and the cap: cheap enough to compute
  // whether or not they are needed), found with the lookup below.
  std::vector<float>& distance = distance_;
  distance.resize(instances.size());
  // Blocks of instances gone this frame (or now showing another mesh) go back to their mesh's
  // free list first, so this frame's newcomers can take them; so do blocks of another level than
  // the instance's now (a new block of the right size is handed out below and relit first, as
  // never lit). One lookup per instance here, which also sums the texels the instances want.
  std::vector<std::uint32_t>& level = level_;
  level.resize(instances.size());
  // Per instance: first whether its block changes level, below its state in the relight list.
  std::vector<std::uint8_t>& flag = flag_;
  flag.resize(instances.size());
  auto texelsOf = [&](std::uint32_t i) -> std::uint32_t {
    const std::uint32_t mesh = instances[i].info.x;
    if (mesh >= meshTexels.size() || meshTexels[mesh] == 0) return 0u;
    return byDistance ? levels.texels[mesh * kLevels + level[i]] : meshTexels[mesh];
  };
  const std::uint64_t wanted =
      parallelSum<std::uint64_t>(instances.size(), [&](std::size_t i) -> std::uint64_t {
        const gs::ObjectInstanceGpu& inst = instances[i];
        const glm::vec3 lo(inst.boundsMin), hi(inst.boundsMax);
        distance[i] = glm::length(glm::max(glm::max(lo - viewer, viewer - hi), glm::vec3(0.0f)));
        Block* block = find(inst.info.z);
        const bool sameMesh = block && block->mesh == inst.info.x;
        if (sameMesh) block->seenFrame = frame_;
        level[i] = 0;
        flag[i] = 0;
        if (byDistance) {
          const int current = sameMesh ? int(block->level) : -1;
          level[i] = levelAt(distance[i], levels.beyond, current);
          flag[i] = current >= 0 && std::uint32_t(current) != level[i] ? 1u : 0u;
        }
        return texelsOf(std::uint32_t(i));
      });
  for (std::uint32_t i = 0; i < instances.size(); ++i) {
    if (!flag[i]) continue;
    release(instances[i].info.z);
    ++stats_.relevelled;
  }
  for (std::size_t k = 0; k < live_.size();) {
    const std::uint32_t id = live_[k];
    if (blocks_[id].seenFrame != frame_) {
      release(id);  // the last live id moves to k: look at k again
    } else {
      ++k;
    }
  }
  // Over the cap: keep the nearest instances whose blocks fit, hand out blocks nearest first,
  // and evict the rest (their blocks return to the free lists before anyone allocates).
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
  // Instances that hold a block: their light's place and relight key, in parallel. Those that
  // need a new block are flagged and served after, serially, in `order` (nearest first when over
  // the cap), as the free lists and the atlas's end are shared.
  std::vector<std::int64_t>& key = key_;
  key.resize(instances.size());
  auto keyOf = [&](const gs::ObjectInstanceGpu& inst, const Block& block) {
    const bool moved = (inst.info.y & gs::kObjectFlagMoved) != 0u;
    std::int64_t k = std::int64_t(block.litFrame) - (moved ? kMovedBoost : 0);
    if (block.litFrame < lightsFrame_) k -= kLightsChangedBoost;
    if (block.litFrame == 0) k = std::numeric_limits<std::int64_t>::min();
    return k;
  };
  struct Counts {
    std::uint32_t withCards = 0, overBudget = 0;
    std::uint64_t liveTexels = 0;
    std::array<std::uint32_t, kLevels> atLevel{};
    Counts& operator+=(const Counts& o) {
      withCards += o.withCards;
      overBudget += o.overBudget;
      liveTexels += o.liveTexels;
      for (std::uint32_t l = 0; l < kLevels; ++l) atLevel[l] += o.atLevel[l];
      return *this;
    }
    Counts operator+(const Counts& o) const {
      Counts c = *this;
      return c += o;
    }
  };
  enum : std::uint8_t { kNone = 0, kLit = 1, kNeedsBlock = 2 };
  const Counts counts = parallelSum<Counts>(instances.size(), [&](std::size_t i) {
    Counts c;
    gs::ObjectInstanceGpu& inst = instances[i];
    inst.info.w = gs::kNoCardLight;
    flag[i] = kNone;
    const std::uint32_t texels = texelsOf(std::uint32_t(i));
    if (texels == 0) return c;
    if (!kept[i]) {
      ++c.overBudget;
      return c;
    }
    const Block* found = find(inst.info.z);
    if (!found) {
      flag[i] = kNeedsBlock;
      return c;
    }
    inst.info.w = found->base | found->level << gs::kCardLightLevelShift;
    ++c.withCards;
    ++c.atLevel[found->level];
    c.liveTexels += texels;
    key[i] = keyOf(inst, *found);
    flag[i] = kLit;
    return c;
  });
  stats_.withCards += counts.withCards;
  stats_.overBudget += counts.overBudget;
  stats_.liveTexels += counts.liveTexels;
  for (std::uint32_t l = 0; l < kLevels; ++l) stats_.atLevel[l] += counts.atLevel[l];
  for (std::uint32_t i : order) {
    if (flag[i] != kNeedsBlock) continue;
    gs::ObjectInstanceGpu& inst = instances[i];
    const std::uint32_t mesh = inst.info.x;
    const std::uint32_t texels = texelsOf(i);
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
    const Block& added = insert(inst.info.z, block);
    inst.info.w = added.base | added.level << gs::kCardLightLevelShift;
    ++stats_.withCards;
    ++stats_.atLevel[added.level];
    stats_.liveTexels += texels;
    key[i] = keyOf(inst, added);
    flag[i] = kLit;
  }
  // The `budget` smallest keys (ties: the lower index) among the lit instances, in parallel:
  // each chunk of instances keeps its own `budget` smallest, and the smallest of all lie among
  // those, so only the chunks' survivors are selected from serially.
  auto byKey = [](const Candidate& a, const Candidate& b) {
    return a.key != b.key ? a.key < b.key : a.index < b.index;
  };
  const std::size_t chunks = (instances.size() + kInstancesPerTask - 1) / kInstancesPerTask;
  if (chunkCandidates_.size() < chunks) chunkCandidates_.resize(chunks);
  tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
    std::vector<Candidate>& local = chunkCandidates_[c];
    local.clear();
    const std::size_t end = std::min(instances.size(), (c + 1) * kInstancesPerTask);
    for (std::size_t i = c * kInstancesPerTask; i < end; ++i)
      if (flag[i] == kLit) local.push_back({key[i], std::uint32_t(i)});
    if (local.size() > budget) {
      std::nth_element(local.begin(), local.begin() + budget, local.end(), byKey);
      local.resize(budget);
    }
  });
  std::vector<Candidate>& candidates = candidates_;
  candidates.clear();
  for (std::size_t c = 0; c < chunks; ++c)
    candidates.insert(candidates.end(), chunkCandidates_[c].begin(), chunkCandidates_[c].end());
  const std::size_t take = std::min<std::size_t>(budget, candidates.size());
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
  stats_.maxStaleFrames = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, instances.size(), kInstancesPerTask), std::uint64_t(0),
      [&](const tbb::blocked_range<std::size_t>& range, std::uint64_t stale) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          if (flag[i] != kLit) continue;
          const std::uint64_t lit = blocks_[instances[i].info.z].litFrame;
          stale = std::max(stale, lit == 0 ? frame_ : frame_ - lit);
        }
        return stale;
      },
      [](std::uint64_t a, std::uint64_t b) { return std::max(a, b); });
  stats_.relit = std::uint32_t(relight.size());
  return relight;
}

}  // namespace sdfstream
