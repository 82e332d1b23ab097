// Which light-cache pages to relight this frame, within a budget of pages per frame.
//
// The light cache (gi/light_cache.h) stores each surface voxel's direct light. A page's light goes
// out of date when its brick arrives or changes (streaming, scrolling), when a moving object's
// shadow may cross it, or when the lights change. Relighting every such page at once is what a
// light switch needs, but a sun that moves every frame (time of day) then relights the whole
// stack every frame: 2.7 ms for Sponza on an H200, 2.6 s a frame on lavapipe. With a budget, the
// work spreads over frames the way the Godot SDFGI slides spread it ("Caching light hits": a
// frame of delay for high temporal coherency) and Lumen and Flax budget their surface caches:
//  1. pages whose brick is new and was never lit go first (their slot holds another brick's
//     light or none), but while other pages wait they get at most half the budget: a fast
//     fly-through can stream in more pages a frame than the budget;
//  2. the rest of the budget goes to the pages that have been out of date longest, oldest first
//     (first in, first out), so with R resident pages and a budget of B no page waits more than
//     about ceil(R / B) frames however often the lights change, ceil(R / (B / 2)) while
//     streaming fills the other half: that is the staleness bound, reported per frame.
// A page that goes out of date again while it waits keeps its place in the queue.
// Without a budget (kRelightEveryPage) every out-of-date page is relit each frame, as before.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "streaming/cascade_stack.h"

namespace sdfstream {

constexpr std::uint32_t kRelightEveryPage = std::numeric_limits<std::uint32_t>::max();

struct LightRelightStats {
  std::uint32_t selected = 0;      // pages handed to the light cache this frame
  std::uint32_t pending = 0;       // resident pages still out of date after this frame's relight
  std::uint32_t unlitPending = 0;  // of those, pages whose brick has never been lit
  // Frames the longest-waiting resident page has been out of date once this frame's relight is
  // done (0: every resident page is up to date).
  std::uint32_t maxStalenessFrames = 0;
};

class LightRelightQueue {
 public:
  // pageBudget: pages relit per frame at most, or kRelightEveryPage. Throws
  // std::invalid_argument for 0.
  explicit LightRelightQueue(std::uint32_t pageBudget = kRelightEveryPage);

  // One frame. `changedPages`: pages whose brick changed (lightDirtyPages without the lights'
  // change, sorted); `shadowedPages`: pages whose light moving objects may have changed
  // (objectShadowPages); lightsChanged: the lights differ from the last frame's, so every
  // resident page is out of date. Pages not resident in `image` are forgotten. Returns the pages
  // to relight now, sorted and distinct, at most the budget; they count as up to date from here.
  std::vector<std::uint32_t> select(const CascadeStackImage& image,
                                    std::span<const std::uint32_t> changedPages,
                                    std::span<const std::uint32_t> shadowedPages,
                                    bool lightsChanged);

  const LightRelightStats& stats() const { return stats_; }
  std::uint32_t pageBudget() const { return budget_; }
  // A new budget from the next select() on; the queue keeps its order. Throws as the constructor.
  void setPageBudget(std::uint32_t pageBudget);

 private:
  static constexpr std::uint64_t kUpToDate = std::numeric_limits<std::uint64_t>::max();
  struct PageState {
    std::uint64_t outOfDateSince = kUpToDate;  // frame its light first went out of date
    bool unlit = false;                        // its brick has not been lit yet
  };

  std::uint32_t budget_;
  std::uint64_t frame_ = 0;       // select() calls so far
  std::vector<PageState> pages_;  // per global page (cascade * 4096 + entry)
  LightRelightStats stats_;
};

}  // namespace sdfstream
