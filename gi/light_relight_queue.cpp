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
  for (std::uint32_t p : changedPages)
    if (p < count) pages_[p] = PageState{frame, true};
  for (std::uint32_t p : shadowedPages)
    if (p < count && pages_[p].outOfDateSince == kUpToDate) pages_[p].outOfDateSince = frame;

  std::vector<std::uint32_t> waiting;
  for (std::uint32_t p = 0; p < count; ++p) {
    PageState& s = pages_[p];
    if ((image.pageTables[p] & gpu_shared::kPageResidentBit) == 0u) {
      s = PageState{};  // its light is rebuilt from scratch when a brick arrives
      continue;
    }
    if (lightsChanged && s.outOfDateSince == kUpToDate) s.outOfDateSince = frame;
    if (s.outOfDateSince != kUpToDate) waiting.push_back(p);
  }

  stats_ = LightRelightStats{};
  if (waiting.size() > budget_) {
    // Never-lit bricks first, then the longest out of date; the page index breaks ties so the
    // order is deterministic.
    const auto first = [this](std::uint32_t a, std::uint32_t b) {
      const PageState& x = pages_[a];
      const PageState& y = pages_[b];
      if (x.unlit != y.unlit) return x.unlit;
      if (x.outOfDateSince != y.outOfDateSince) return x.outOfDateSince < y.outOfDateSince;
      return a < b;
    };
    const auto cut = waiting.begin() + budget_;
    std::nth_element(waiting.begin(), cut, waiting.end(), first);
    std::uint64_t oldest = kUpToDate;
    for (auto it = cut; it != waiting.end(); ++it) {
      const PageState& s = pages_[*it];
      stats_.unlitPending += s.unlit ? 1u : 0u;
      oldest = std::min(oldest, s.outOfDateSince);
    }
    stats_.pending = std::uint32_t(waiting.end() - cut);
    // Frames shown with out-of-date light so far, this one included.
    stats_.maxStalenessFrames = std::uint32_t(frame + 1 - oldest);
    waiting.erase(cut, waiting.end());
    std::sort(waiting.begin(), waiting.end());
  }
  for (std::uint32_t p : waiting) pages_[p] = PageState{};
  stats_.selected = std::uint32_t(waiting.size());
  return waiting;
}

}  // namespace sdfstream
