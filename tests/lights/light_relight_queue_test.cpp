// LightRelightQueue: which light-cache pages are relit each frame within a page budget. Pure host
// logic over hand-built page tables: never-lit bricks first, then the longest out of date, the
// staleness bound ceil(resident / budget) under lights that change every frame, and the counts
// it reports.
#include <algorithm>
#include <map>
#include <numeric>
#include <stdexcept>

#include <gtest/gtest.h>

#include "gi/light_cache.h"
#include "gi/light_relight_queue.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream {
namespace {
using gpu_shared::kCascadePageCount;
using gpu_shared::kPageResidentBit;

// One cascade whose first `resident` pages hold bricks (slot = page index).
CascadeStackImage stackWithResidentPages(std::uint32_t resident) {
  CascadeStackImage image;
  image.pageTables.assign(kCascadePageCount, 0u);
  for (std::uint32_t p = 0; p < resident; ++p) image.pageTables[p] = kPageResidentBit | p;
  image.params.resize(1);
  image.voxelSize0 = 0.1;
  return image;
}

std::vector<std::uint32_t> allPages(std::uint32_t n) {
  std::vector<std::uint32_t> v(n);
  std::iota(v.begin(), v.end(), 0u);
  return v;
}

TEST(LightRelightQueue, WithoutABudgetEveryOutOfDatePageIsRelitAtOnce) {
  const CascadeStackImage image = stackWithResidentPages(300);
  LightRelightQueue queue;
  EXPECT_EQ(queue.select(image, allPages(300), {}, true), allPages(300));
  EXPECT_EQ(queue.stats().pending, 0u);
  EXPECT_TRUE(queue.select(image, {}, {}, false).empty()) << "nothing changed";
  const std::vector<std::uint32_t> shadowed{5, 17, 250};
  EXPECT_EQ(queue.select(image, {}, shadowed, false), shadowed);
  EXPECT_EQ(queue.select(image, {}, {}, true), allPages(300)) << "the lights changed";
  EXPECT_EQ(queue.stats().maxStalenessFrames, 0u);
}

TEST(LightRelightQueue, AMovingSunRelightsEveryPageWithinResidentOverBudgetFrames) {
  constexpr std::uint32_t kResident = 1000, kBudget = 64;
  constexpr std::uint32_t kBound = (kResident + kBudget - 1) / kBudget;  // 16 frames
  constexpr int kSettled = 100;  // the first lighting of 1,000 new bricks is done well before
  const CascadeStackImage image = stackWithResidentPages(kResident);
  LightRelightQueue queue(kBudget);
  std::vector<int> lastLit(kResident, -1);
  std::uint32_t worstGap = 0, worstReported = 0;
  for (int frame = 0; frame < 300; ++frame) {
    const auto changed = frame == 0 ? allPages(kResident) : std::vector<std::uint32_t>{};
    const std::vector<std::uint32_t> relit = queue.select(image, changed, {}, true);
    ASSERT_EQ(relit.size(), kBudget) << "frame " << frame;
    ASSERT_TRUE(std::is_sorted(relit.begin(), relit.end()));
    ASSERT_EQ(std::adjacent_find(relit.begin(), relit.end()), relit.end()) << "distinct";
    for (std::uint32_t p : relit) {
      if (frame >= kSettled) worstGap = std::max(worstGap, std::uint32_t(frame - lastLit[p]));
      lastLit[p] = frame;
    }
    EXPECT_EQ(queue.stats().selected, kBudget);
    EXPECT_EQ(queue.stats().pending, kResident - kBudget);
    if (frame >= kSettled) {
      EXPECT_EQ(queue.stats().unlitPending, 0u);
      worstReported = std::max(worstReported, queue.stats().maxStalenessFrames);
    }
  }
  // First in, first out: every page comes round again after the same number of frames.
  EXPECT_EQ(worstGap, kBound);
  EXPECT_LE(worstReported, kBound);
  EXPECT_GE(worstReported, kBound - 1);
}

TEST(LightRelightQueue, NewBricksGoFirstWithHalfTheBudgetWhileOthersWait) {
  const CascadeStackImage image = stackWithResidentPages(100);
  const CascadeStackImage half = stackWithResidentPages(50);
  LightRelightQueue queue(10);
  // Nothing else waits: new bricks take the whole budget.
  EXPECT_EQ(queue.select(half, allPages(50), {}, false), allPages(10));
  for (int f = 0; f < 4; ++f) queue.select(half, {}, {}, false);
  EXPECT_EQ(queue.stats().pending, 0u);
  // The lights change once (all 50 out of date), then pages 50..99 stream in.
  queue.select(half, {}, {}, true);  // relights 0..9
  std::vector<std::uint32_t> arriving(50);
  std::iota(arriving.begin(), arriving.end(), 50u);
  const std::vector<std::uint32_t> relit = queue.select(image, arriving, {}, false);
  EXPECT_EQ(relit, (std::vector<std::uint32_t>{10, 11, 12, 13, 14, 50, 51, 52, 53, 54}))
      << "half for the new bricks, half for the longest out of date";
  EXPECT_EQ(queue.stats().unlitPending, 45u);
  EXPECT_EQ(queue.stats().pending, 45u + 35u);
  EXPECT_EQ(queue.stats().maxStalenessFrames, 2u);
  // Fewer new bricks than half the budget: the out-of-date pages take the rest.
  LightRelightQueue other(10);
  other.select(half, allPages(50), {}, false);
  for (int f = 0; f < 4; ++f) other.select(half, {}, {}, false);
  other.select(half, {}, {}, true);  // all 50 out of date; 0..9 relit
  const std::vector<std::uint32_t> two{50, 51};
  EXPECT_EQ(other.select(stackWithResidentPages(52), two, {}, false),
            (std::vector<std::uint32_t>{10, 11, 12, 13, 14, 15, 16, 17, 50, 51}));
}

TEST(LightRelightQueue, AShadowedPageKeepsItsPlaceAndAnEvictedPageIsForgotten) {
  const CascadeStackImage image = stackWithResidentPages(40);
  LightRelightQueue queue(4);
  for (int f = 0; f < 10; ++f)
    queue.select(image, f == 0 ? allPages(40) : std::vector<std::uint32_t>{}, {}, false);
  ASSERT_EQ(queue.stats().pending, 0u);
  // Page 30 goes out of date, then every page through a light change; 30 is the oldest.
  queue.select(image, {}, std::vector<std::uint32_t>{30}, false);  // relit at once (budget)
  const std::vector<std::uint32_t> shadowed{30};
  queue.select(image, {}, {}, true);  // 0..3 relit, 4..39 wait
  const auto next = queue.select(image, {}, shadowed, false);
  EXPECT_EQ(next, (std::vector<std::uint32_t>{4, 5, 6, 7}))
      << "a page shadowed again does not jump the queue";
  // Pages 8..39 leave the stack: they are no longer pending and come back as new bricks.
  const CascadeStackImage shrunk = stackWithResidentPages(8);
  EXPECT_TRUE(queue.select(shrunk, {}, {}, false).empty());
  EXPECT_EQ(queue.stats().pending, 0u);
  EXPECT_EQ(queue.stats().maxStalenessFrames, 0u);
}

// A page whose brick changes every frame (a fly-through scrolling back and forth over it) keeps
// its place in the queue: it is lit within the bound, not starved behind newer arrivals.
TEST(LightRelightQueue, ABrickThatKeepsChangingIsNotStarved) {
  constexpr std::uint32_t kResident = 400, kBudget = 8;
  const CascadeStackImage image = stackWithResidentPages(kResident);
  LightRelightQueue queue(kBudget);
  queue.select(image, allPages(kResident), {}, false);
  int litAt = -1;
  for (int frame = 1; frame < 200 && litAt < 0; ++frame) {
    // Page 399 changes every frame, and so do 40 others: more arrivals than the budget.
    std::vector<std::uint32_t> changed{399};
    for (std::uint32_t k = 0; k < 40; ++k) changed.push_back((std::uint32_t(frame) * 40 + k) % 399);
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
    const auto relit = queue.select(image, changed, {}, true);
    if (std::binary_search(relit.begin(), relit.end(), 399u)) litAt = frame;
  }
  ASSERT_GE(litAt, 1) << "page 399 never lit";
  EXPECT_LE(litAt, int(kResident / (kBudget / 2)) + 1);
}

TEST(LightRelightQueue, ABudgetOfNoPagesIsRefused) {
  EXPECT_THROW(LightRelightQueue(0), std::invalid_argument);
  EXPECT_EQ(LightCacheSettings{}.relightPageBudget, kRelightEveryPage);
}

}  // namespace
}  // namespace sdfstream
