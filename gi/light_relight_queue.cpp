#include "gi/light_relight_queue.h"

#include <algorithm>
#include <stdexcept>

#include "shaders/shared/sdf_layout.h"

namespace sdfstream {

LightRelightQueue::LightRelightQueue(std::uint32_t pageBudget) { setPageBudget(pageBudget); }

void LightRelightQueue::setPageBudget(std::uint32_t pageBudget) {
  if (pageBudget == 0)
    throw std::invalid_argument("LightRelightQueue: a budget of 0 pages would never relight");
  budget_ = pageBudget;
}

std::vector<std::uint32_t> LightRelightQueue::select(const CascadeStackImage& image,
                                                     std::span<const std::uint32_t> changedPages,
                                                     std::span<const std::uint32_t> shadowedPages,
                                                     bool lightsChanged) {
  const std::uint64_t frame = frame_++;
  const std::size_t count = image.pageTables.size();
  // A new cascade count: lightDirtyPages lists every resident page as changed then.
  if (pages_.size() != count) pages_.assign(count, PageState{});
  // A brick that changes again while it waits keeps its place: a page the fly-through keeps
  // rewriting (scrolling back and forth) would otherwise always be the newest and never lit.
  for (std::uint32_t p : changedPages)
    if (p < count) pages_[p] = PageState{std::min(pages_[p].outOfDateSince, frame), true};
  for (std::uint32_t p : shadowedPages)
    if (p < count && pages_[p].outOfDateSince == kUpToDate) pages_[p].outOfDateSince = frame;

  // Never-lit bricks and pages whose light went out of date wait in separate queues.
  std::vector<std::uint32_t> unlit, outOfDate;
  for (std::uint32_t p = 0; p < count; ++p) {
    PageState& s = pages_[p];
    if ((image.pageTables[p] & gpu_shared::kPageResidentBit) == 0u) {
      s = PageState{};  // its light is rebuilt from scratch when a brick arrives
      continue;
    }
    if (lightsChanged && s.outOfDateSince == kUpToDate) s.outOfDateSince = frame;
    if (s.outOfDateSince != kUpToDate) (s.unlit ? unlit : outOfDate).push_back(p);
  }

  stats_ = LightRelightStats{};
  std::uint64_t oldest = kUpToDate;
  // Keeps the `take` longest-waiting pages of `queue` (the page index breaks ties, so the order
  // is deterministic) and counts the others as pending.
  const auto takeOldest = [&](std::vector<std::uint32_t>& queue, std::size_t take) {
    if (queue.size() <= take) return;
    const auto first = [this](std::uint32_t a, std::uint32_t b) {
      const PageState& x = pages_[a];
      const PageState& y = pages_[b];
      return x.outOfDateSince != y.outOfDateSince ? x.outOfDateSince < y.outOfDateSince : a < b;
    };
    const auto cut = queue.begin() + std::ptrdiff_t(take);
    std::nth_element(queue.begin(), cut, queue.end(), first);
    for (auto it = cut; it != queue.end(); ++it) {
      oldest = std::min(oldest, pages_[*it].outOfDateSince);
      stats_.unlitPending += pages_[*it].unlit ? 1u : 0u;
    }
    stats_.pending += std::uint32_t(queue.end() - cut);
    queue.erase(cut, queue.end());
  };
  // New bricks come first, but while out-of-date pages wait they get at most half the budget:
  // a fast fly-through can stream more pages a frame than the budget, and the other half keeps
  // the staleness of the rest bounded (ceil(resident / (budget / 2)) frames at worst).
  const std::size_t budget = budget_;
  const std::size_t takeOutOfDate =
      std::min(outOfDate.size(), std::max(budget / 2, budget - std::min(budget, unlit.size())));
  const std::size_t takeUnlit = std::min(unlit.size(), budget - takeOutOfDate);
  takeOldest(unlit, takeUnlit);
  takeOldest(outOfDate, takeOutOfDate);
  // Frames shown with out-of-date light so far, this one included.
  if (oldest != kUpToDate) stats_.maxStalenessFrames = std::uint32_t(frame + 1 - oldest);
  std::vector<std::uint32_t> waiting = std::move(unlit);
  waiting.insert(waiting.end(), outOfDate.begin(), outOfDate.end());
  std::sort(waiting.begin(), waiting.end());
  for (std::uint32_t p : waiting) pages_[p] = PageState{};
  stats_.selected = std::uint32_t(waiting.size());
  return waiting;
}

}  // namespace sdfstream
