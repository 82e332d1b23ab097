// objectShadowPages (gi/light_cache.h): the pages whose direct light a moving object may have
// changed, so the light cache relights only where objects moved (issue 7 item 6).
#include <algorithm>

#include "gi/light_cache.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream {
namespace gs = gpu_shared;

namespace {
struct Box {
  glm::vec3 lo, hi;
};

// The part of the box's shadow between distances s0 and s1 from it: every corner moved s0 and s1
// stack voxels away from the light, as one box. Marking the shadow piece by piece follows a
// slanted shadow closely, where one box around the whole sweep would cover a quarter of a cascade.
Box shadowSegment(const Box& b, const gs::GpuLight& light, float s0, float s1) {
  Box out{glm::vec3(1e30f), glm::vec3(-1e30f)};
  const bool sun = std::uint32_t(light.positionType.w + 0.5f) == gs::kLightSun;
  const glm::vec3 lightPos(light.positionType);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? b.hi.x : b.lo.x, (corner & 2) ? b.hi.y : b.lo.y,
                      (corner & 4) ? b.hi.z : b.lo.z);
    const glm::vec3 away = sun ? -glm::normalize(glm::vec3(light.direction)) : p - lightPos;
    const glm::vec3 u = away / std::max(glm::length(away), 1e-6f);
    for (float sv : {s0, s1}) {
      out.lo = glm::min(out.lo, p + u * sv);
      out.hi = glm::max(out.hi, p + u * sv);
    }
  }
  return out;
}

bool contains(const Box& b, glm::vec3 p) {
  return glm::all(glm::greaterThanEqual(p, b.lo)) && glm::all(glm::lessThanEqual(p, b.hi));
}
}  // namespace

std::vector<std::uint32_t> objectShadowPages(const CascadeStackImage& stack,
                                             std::span<const WorldBox> changed,
                                             std::span<const gs::GpuLight> lights) {
  std::vector<std::uint32_t> pages;
  if (changed.empty() || stack.params.empty()) return pages;
  const float reach = 128.0f * stack.params.back().offsetScale.w * 1.7320508f;
  // Pages are marked by the range each swept box covers, so the cost is the pages covered (and
  // stops once a cascade is all marked), not pages × boxes: thousands of objects move at once.
  const std::size_t cascades = stack.params.size();
  std::vector<std::uint8_t> marked(cascades * gs::kCascadePageCount, 0);
  std::vector<std::uint32_t> markedCount(cascades, 0);
  auto mark = [&](const Box& b) {
    for (std::uint32_t c = 0; c < cascades; ++c) {
      if (markedCount[c] == gs::kCascadePageCount) continue;
      const gs::CascadeTraceParams& p = stack.params[c];
      const glm::vec3 origin(p.offsetScale);
      const float pageEdge = 8.0f * p.offsetScale.w;
      const glm::vec3 lo = (b.lo - origin) / pageEdge, hi = (b.hi - origin) / pageEdge;
      if (hi.x < 0 || hi.y < 0 || hi.z < 0 || lo.x > 16 || lo.y > 16 || lo.z > 16) continue;
      const glm::ivec3 a = glm::clamp(glm::ivec3(glm::floor(lo)), glm::ivec3(0), glm::ivec3(15));
      const glm::ivec3 z = glm::clamp(glm::ivec3(glm::floor(hi)), glm::ivec3(0), glm::ivec3(15));
      for (int pz = a.z; pz <= z.z; ++pz)
        for (int py = a.y; py <= z.y; ++py)
          for (int px = a.x; px <= z.x; ++px) {
            const std::uint32_t entry = ((std::uint32_t(px) + p.toroidal.x) & 15u) +
                                        16u * (((std::uint32_t(py) + p.toroidal.y) & 15u) +
                                               16u * ((std::uint32_t(pz) + p.toroidal.z) & 15u));
            std::uint8_t& m = marked[c * gs::kCascadePageCount + entry];
            if (!m) {
              m = 1;
              ++markedCount[c];
            }
          }
    }
  };
  for (const WorldBox& w : changed) {
    const Box b{stack.toStack(w.min), stack.toStack(w.max)};
    mark(b);  // the object's own surfaces and what it covers
    for (const gs::GpuLight& l : lights) {
      if (l.shape.w <= 0.5f) continue;
      const bool sun = std::uint32_t(l.positionType.w + 0.5f) == gs::kLightSun;
      if (!sun && contains(b, glm::vec3(l.positionType))) {  // a light inside: anything goes
        mark(Box{glm::vec3(-1e30f), glm::vec3(1e30f)});
        continue;
      }
      // Segments a page long near the object, growing by a quarter of their distance after.
      for (float s0 = 0.0f; s0 < reach;) {
        const float s1 = std::min(reach, s0 + std::max(8.0f, 0.25f * s0));
        mark(shadowSegment(b, l, s0, s1));
        s0 = s1;
      }
    }
  }
  for (std::uint32_t c = 0; c < cascades; ++c) {
    const std::uint32_t base = stack.params[c].toroidal.w;
    for (std::uint32_t e = 0; e < gs::kCascadePageCount; ++e)
      if (marked[c * gs::kCascadePageCount + e] &&
          (stack.pageTables[base + e] & gs::kPageResidentBit))
        pages.push_back(base + e);
  }
  return pages;  // ascending: cascades in order, entries in order
}

}  // namespace sdfstream
