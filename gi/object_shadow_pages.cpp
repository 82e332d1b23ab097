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
  bool overlaps(const Box& o) const {
    return lo.x <= o.hi.x && o.lo.x <= hi.x && lo.y <= o.hi.y && o.lo.y <= hi.y && lo.z <= o.hi.z &&
           o.lo.z <= hi.z;
  }
};

// The box plus its shadow: every corner swept `reach` stack voxels away from the light.
Box sweptAway(const Box& b, const gs::GpuLight& light, float reach) {
  Box out = b;
  const bool sun = std::uint32_t(light.positionType.w + 0.5f) == gs::kLightSun;
  const glm::vec3 lightPos(light.positionType);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? b.hi.x : b.lo.x, (corner & 2) ? b.hi.y : b.lo.y,
                      (corner & 4) ? b.hi.z : b.lo.z);
    glm::vec3 away = sun ? -glm::normalize(glm::vec3(light.direction)) : p - lightPos;
    const float len = glm::length(away);
    if (len < 1e-6f) return Box{glm::vec3(-1e30f), glm::vec3(1e30f)};  // light inside: all
    const glm::vec3 q = p + away / len * reach;
    out.lo = glm::min(out.lo, q);
    out.hi = glm::max(out.hi, q);
  }
  return out;
}
}  // namespace

std::vector<std::uint32_t> objectShadowPages(const CascadeStackImage& stack,
                                             std::span<const WorldBox> changed,
                                             std::span<const gs::GpuLight> lights) {
  std::vector<std::uint32_t> pages;
  if (changed.empty() || stack.params.empty()) return pages;
  const float reach = 128.0f * stack.params.back().offsetScale.w * 1.7320508f;
  std::vector<Box> swept;
  for (const WorldBox& w : changed) {
    const Box b{stack.toStack(w.min), stack.toStack(w.max)};
    swept.push_back(b);  // the object's own surfaces and what it covers
    for (const gs::GpuLight& l : lights)
      if (l.shape.w > 0.5f) swept.push_back(sweptAway(b, l, reach));
  }
  for (std::uint32_t c = 0; c < stack.params.size(); ++c) {
    const gs::CascadeTraceParams& p = stack.params[c];
    const glm::vec3 origin(p.offsetScale);
    const float pageEdge = 8.0f * p.offsetScale.w;
    for (std::uint32_t pz = 0; pz < 16; ++pz)
      for (std::uint32_t py = 0; py < 16; ++py)
        for (std::uint32_t px = 0; px < 16; ++px) {
          const std::uint32_t entry =
              p.toroidal.w + ((px + p.toroidal.x) & 15u) +
              16u * (((py + p.toroidal.y) & 15u) + 16u * ((pz + p.toroidal.z) & 15u));
          if ((stack.pageTables[entry] & gs::kPageResidentBit) == 0u) continue;
          const Box page{origin + glm::vec3(px, py, pz) * pageEdge,
                         origin + glm::vec3(px + 1, py + 1, pz + 1) * pageEdge};
          if (std::any_of(swept.begin(), swept.end(),
                          [&](const Box& b) { return b.overlaps(page); }))
            pages.push_back(entry);
        }
  }
  std::sort(pages.begin(), pages.end());
  return pages;
}

}  // namespace sdfstream
