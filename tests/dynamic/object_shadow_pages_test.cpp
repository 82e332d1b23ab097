// objectShadowPages against a brute-force sweep: every page that a point of a changed box, moved
// away from a shadow-casting light in small steps, passes through must be marked (the light
// cache relights nothing else after a move, so a page missed here would keep a stale shadow).
// Also bounds how much more than the sweep it marks.
#include <algorithm>
#include <cstdio>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "gi/light_cache.h"
#include "shaders/shared/light_layout.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream {
namespace {
namespace gs = gpu_shared;

// Three nested cascades around cascade 0, each scrolled by a different toroidal offset; every
// page resident. Stack space = world space (voxel 0 = 1 m, cascade 0 from the origin).
CascadeStackImage nestedStack() {
  CascadeStackImage image;
  image.voxelSize0 = 1.0;
  for (std::uint32_t c = 0; c < 3; ++c) {
    gs::CascadeTraceParams p{};
    const float scale = float(1u << c);
    const float lo = -64.0f * (scale - 1.0f);  // centred on cascade 0's centre (64, 64, 64)
    p.offsetScale = glm::vec4(lo, lo, lo, scale);
    p.toroidal = glm::uvec4(3u * c + 1u, 5u * c, 7u * c + 2u, c * gs::kCascadePageCount);
    image.params.push_back(p);
  }
  image.pageTables.assign(image.params.size() * gs::kCascadePageCount, gs::kPageResidentBit);
  return image;
}

// The page entry holding stack point q in cascade c, or -1 outside it.
long pageEntry(const CascadeStackImage& image, std::uint32_t c, glm::vec3 q) {
  const gs::CascadeTraceParams& p = image.params[c];
  const glm::vec3 g = (q - glm::vec3(p.offsetScale)) / (8.0f * p.offsetScale.w);
  if (glm::any(glm::lessThan(g, glm::vec3(0.0f))) ||
      glm::any(glm::greaterThanEqual(g, glm::vec3(16.0f))))
    return -1;
  const glm::uvec3 i = glm::uvec3(glm::floor(g));
  return long(p.toroidal.w + ((i.x + p.toroidal.x) & 15u) +
              16u * (((i.y + p.toroidal.y) & 15u) + 16u * ((i.z + p.toroidal.z) & 15u)));
}

// Sweeps 4³ points of every box (faces included) away from each light in quarter-voxel steps
// until they leave the outermost cascade, collecting the pages they pass through.
std::set<std::uint32_t> sweptPages(const CascadeStackImage& image,
                                   const std::vector<WorldBox>& boxes,
                                   const std::vector<gs::GpuLight>& lights) {
  std::set<std::uint32_t> pages;
  const float outer = 128.0f * image.params.back().offsetScale.w;
  for (const WorldBox& w : boxes)
    for (int k = 0; k < 64; ++k) {
      const glm::vec3 t(float(k % 4) / 3.0f, float((k / 4) % 4) / 3.0f, float(k / 16) / 3.0f);
      const glm::vec3 x = glm::mix(glm::vec3(w.min), glm::vec3(w.max), t);
      for (const gs::GpuLight& l : lights) {
        const bool sun = std::uint32_t(l.positionType.w + 0.5f) == gs::kLightSun;
        const glm::vec3 u = sun ? -glm::normalize(glm::vec3(l.direction))
                                : glm::normalize(x - glm::vec3(l.positionType));
        for (float s = 0.0f; s < 2.0f * outer; s += 0.25f)
          for (std::uint32_t c = 0; c < image.params.size(); ++c) {
            const long e = pageEntry(image, c, x + u * s);
            if (e >= 0) pages.insert(std::uint32_t(e));
          }
      }
    }
  return pages;
}

gs::GpuLight sun(glm::vec3 towardsLight) {
  gs::GpuLight l{};
  l.positionType = glm::vec4(0.0f, 0.0f, 0.0f, float(gs::kLightSun));
  l.direction = glm::vec4(glm::normalize(towardsLight), 0.0f);
  l.colorIntensity = glm::vec4(1.0f);
  l.shape.w = 1.0f;
  return l;
}

gs::GpuLight point(glm::vec3 position) {
  gs::GpuLight l{};
  l.positionType = glm::vec4(position, float(gs::kLightPoint));
  l.colorIntensity = glm::vec4(1.0f);
  l.shape.w = 1.0f;
  return l;
}

std::vector<WorldBox> randomBoxes(std::mt19937& rng, int count, float spread) {
  std::uniform_real_distribution<float> pos(64.0f - spread, 64.0f + spread), size(0.2f, 6.0f);
  std::vector<WorldBox> boxes;
  for (int i = 0; i < count; ++i) {
    const glm::dvec3 lo(pos(rng), pos(rng), pos(rng));
    boxes.push_back({lo, lo + glm::dvec3(size(rng), size(rng), size(rng))});
  }
  return boxes;
}

TEST(ObjectShadowPages, CoverEveryPageTheSweptBoxesPassThrough) {
  const CascadeStackImage image = nestedStack();
  std::mt19937 rng(7);
  std::size_t sweptTotal = 0, markedTotal = 0, missedTotal = 0;
  for (int trial = 0; trial < 8; ++trial) {
    // Boxes inside cascade 0, beyond it, and (some) outside the whole stack.
    const std::vector<WorldBox> boxes = randomBoxes(rng, 6, trial < 6 ? 70.0f : 300.0f);
    std::uniform_real_distribution<float> dir(-1.0f, 1.0f);
    const std::vector<gs::GpuLight> lights = {
        sun(glm::vec3(dir(rng), 1.0f, dir(rng))), sun(glm::vec3(dir(rng), dir(rng), dir(rng))),
        point(glm::vec3(64.0f) + 40.0f * glm::vec3(dir(rng), dir(rng), dir(rng)))};
    const std::vector<std::uint32_t> marked = objectShadowPages(image, boxes, lights);
    const std::set<std::uint32_t> markedSet(marked.begin(), marked.end());
    ASSERT_EQ(markedSet.size(), marked.size()) << "pages listed twice";
    ASSERT_TRUE(std::is_sorted(marked.begin(), marked.end()));
    const std::set<std::uint32_t> swept = sweptPages(image, boxes, lights);
    for (std::uint32_t p : swept) missedTotal += markedSet.count(p) ? 0 : 1;
    sweptTotal += swept.size();
    markedTotal += marked.size();
  }
  std::printf("[figures] shadow pages: %zu swept by brute force, %zu marked (%.2fx), %zu missed\n",
              sweptTotal, markedTotal, double(markedTotal) / double(sweptTotal), missedTotal);
  EXPECT_EQ(missedTotal, 0u);
  EXPECT_GT(sweptTotal, 500u);  // the trials do cast shadows through the stack
  // Conservative, not everything: at most 2x the pages the shadows really pass through (1.53x
  // measured; the per-box sweep this replaced marked 1.50x).
  EXPECT_LT(double(markedTotal), 2.0 * double(sweptTotal));
}

// Thousands of boxes at once are split into chunks marked in parallel and merged (cells ORed,
// shadow maps by their minimum). A page is marked for a set of boxes exactly when it is marked
// for one of them alone (each box's casters and shadow depths are its own), so the whole set
// must mark the union of the pages each box marks by itself.
TEST(ObjectShadowPages, ManyBoxesMarkTheUnionOfEachBoxAlone) {
  const CascadeStackImage image = nestedStack();
  std::mt19937 rng(19);
  std::uniform_real_distribution<float> pos(-120.0f, 250.0f), size(0.05f, 3.0f);
  std::vector<WorldBox> boxes;
  for (int i = 0; i < 2500; ++i) {
    const glm::dvec3 lo(pos(rng), pos(rng) * 0.2f + 40.0f, pos(rng));
    const float s = i % 10 == 0 ? 4.0f * size(rng) : 0.3f * size(rng);
    boxes.push_back({lo, lo + glm::dvec3(s, 0.5 * s, s)});
  }
  const std::vector<gs::GpuLight> lights = {sun(glm::vec3(0.4f, 1.0f, -0.3f)),
                                            point(glm::vec3(70.0f, 60.0f, 50.0f))};
  const std::vector<std::uint32_t> all = objectShadowPages(image, boxes, lights);
  std::set<std::uint32_t> alone;
  for (const WorldBox& b : boxes) {
    const std::vector<std::uint32_t> one =
        objectShadowPages(image, std::vector<WorldBox>{b}, lights);
    alone.insert(one.begin(), one.end());
  }
  std::printf("[figures] %zu boxes: %zu pages marked together, %zu by the boxes alone\n",
              boxes.size(), all.size(), alone.size());
  EXPECT_EQ(std::vector<std::uint32_t>(alone.begin(), alone.end()), all);
  EXPECT_GT(all.size(), 1000u);
  EXPECT_LT(all.size(), image.pageTables.size());  // not everything
}

TEST(ObjectShadowPages, AnUnshadowedLightAddsOnlyTheBoxesOwnPages) {
  const CascadeStackImage image = nestedStack();
  const std::vector<WorldBox> boxes = {{glm::dvec3(60.0), glm::dvec3(61.0)}};
  gs::GpuLight noShadow = sun(glm::vec3(0.3f, 1.0f, 0.1f));
  noShadow.shape.w = 0.0f;
  // A 1 m box at (60..61)^3 lies in one page of each of the three cascades.
  EXPECT_EQ(objectShadowPages(image, boxes, std::vector<gs::GpuLight>{noShadow}).size(), 3u);
  EXPECT_GT(
      objectShadowPages(image, boxes, std::vector<gs::GpuLight>{sun(glm::vec3(0.3f, 1.0f, 0.1f))})
          .size(),
      3u);
}

}  // namespace
}  // namespace sdfstream
