// The CPU half of gi/light_cache.h: dirty-page selection, push constants and the CPU reference
// LightCacheCpu, which runs shaders/light_math.glsl compiled as C++.
#include <algorithm>
#include <cassert>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <glm/gtc/packing.hpp>

#include "gi/light_cache.h"
#include "shaders/shared/color_codec.h"

namespace sdfstream {
namespace light_detail {
using namespace glm;
using namespace gpu_shared;

// The GLSL functions become member functions; the macros read this object's pointers, which
// point into the CascadeStackImage and the light list of one update.
struct LightCacheShader {
  const std::uint32_t* pageTable = nullptr;
  const std::uint32_t* distanceAtlas = nullptr;
  const std::uint32_t* albedoAtlas = nullptr;
  const std::uint32_t* emissionAtlas = nullptr;
  const CascadeTraceParams* cascades = nullptr;
  const GpuLight* lights = nullptr;

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#define LIGHT_AT(i) lights[i]
#define LIGHT_COUNT_MARCH(m) countMarch(m)
#include "shaders/sdf_trace.glsl"
// light_math.glsl needs sdf_trace.glsl's functions: keep this order (a separate include block).
#include "shaders/light_math.glsl"
#undef SDF_PAGE
#undef SDF_DIST_WORD
#undef SDF_ALBEDO
#undef SDF_EMISSION
#undef SDF_CASCADE
#undef LIGHT_AT
#undef LIGHT_COUNT_MARCH

  // The shadow marches since the counters were last cleared (lightCacheWork).
  std::uint32_t marches = 0, marchSteps = 0, blockedMarches = 0;
  void countMarch(const LightShadowStackMarch& m) {
    ++marches;
    marchSteps += m.steps;
    blockedMarches += m.blocked ? 1u : 0u;
  }

  // Mirrors main() of light_cache.comp; returns false when the cell is not written.
  bool relightCell(std::uint32_t global, std::uint32_t cell, const LightCachePushConstants& pc,
                   std::uint32_t& index, std::uint32_t& value) {
    const std::uint32_t cascade = global / kCascadePageCount;
    if (cascade >= pc.counts.z) return false;
    const std::uint32_t entry = pageTable[global];
    if ((entry & kPageResidentBit) == 0u) return false;
    const std::uint32_t slot = entry & kPagePayloadMask;
    const ivec3 page = lightPageOfEntry(global % kCascadePageCount, cascades[cascade].toroidal);
    const vec3 radiance = lightCacheCellRadiance(
        cascade, page, slot, cell, pc.counts.y, pc.params.x, pc.counts.w, pc.params.y, pc.counts.z);
    index = slot * kBrickMaterialCount + cell;
    value = packRgb9e5(radiance);
    return true;
  }
};

// Brick coordinate (in the cascade's own bricks) held by toroidal entry `entry` of cascade c:
// the cascade's minimum corner in bricks plus the entry's page coordinate.
glm::dvec3 entryBrick(const CascadeStackImage& image, std::uint32_t c, std::uint32_t entry) {
  const CascadeTraceParams& cp = image.params[c];
  const glm::dvec3 corner0 =
      image.voxelSize0 > 0.0 ? image.cascade0MinWorld / image.voxelSize0 : glm::dvec3(0.0);
  const glm::dvec3 corner =
      (corner0 + glm::dvec3(glm::vec3(cp.offsetScale))) / (double(cp.offsetScale.w) * kBrickCells);
  LightCacheShader shader{};
  const glm::ivec3 page = shader.lightPageOfEntry(entry, cp.toroidal);
  return glm::round(corner) + glm::dvec3(page);
}
}  // namespace light_detail

LightCellSteps lightCellSteps(const CascadeStackImage& stack, const gpu_shared::GpuLight& light,
                              std::uint32_t cascade, glm::vec3 p0,
                              const LightCacheSettings& settings) {
  using namespace gpu_shared;
  light_detail::LightCacheShader sh{stack.pageTables.data(),   stack.distanceAtlas->data(),
                                    stack.albedoAtlas->data(), stack.emissionAtlas->data(),
                                    stack.params.data(),       &light};
  const CascadeTraceParams& cp = stack.params[cascade];
  const std::uint32_t cascades = std::uint32_t(stack.params.size());
  const glm::vec3 p = (p0 - glm::vec3(cp.offsetScale)) / cp.offsetScale.w;
  const glm::ivec3 page = sh.sdfPageOf(p);
  const glm::ivec3 cellXyz =
      glm::clamp(glm::ivec3(glm::floor(p - glm::vec3(page) * 8.0f)), glm::ivec3(0), glm::ivec3(7));
  const std::uint32_t cell = std::uint32_t(cellXyz.x + 8 * (cellXyz.y + 8 * cellXyz.z));
  LightCellSteps out;
  const glm::vec3 centre = sh.lightCellCentre(page, cell);
  const light_detail::LightCacheShader::SdfSample smp = sh.sdfSampleCascade(centre, cp.toroidal);
  out.resident = smp.resident;
  out.distance = smp.distance;
  out.inBand = sh.lightSampleIsSurface(smp);
  if (!out.inBand) return out;
  out.normal = sh.sdfNearNormal(centre, cp.toroidal);
  const glm::vec3 surface = centre - out.normal * smp.distance;
  out.surface0 = glm::vec3(cp.offsetScale) + surface * cp.offsetScale.w;
  const glm::vec3 toLight = glm::normalize(glm::vec3(light.direction));
  out.cosine = glm::dot(out.normal, toLight);
  if (out.cosine <= 0.0f) return out;
  const std::uint32_t c = sh.lightFinestCascade(out.surface0, cascades);
  out.shadowCascade = c;
  const float voxel = stack.params[c < cascades ? c : cascades - 1].offsetScale.w;
  const glm::vec3 origin = out.surface0 + out.normal * (0.5f * voxel);
  const light_detail::LightCacheShader::LightShadowRay ray = sh.lightShadowRay(light, origin);
  out.visibility = sh.sdfSoftShadowStack(origin, ray.dir, 0.0f, ray.tMax, settings.maxShadowSteps,
                                         settings.hitEpsilon, cascades, light.shape.z);
  return out;
}

std::int64_t lightMaterialAt(const CascadeStackImage& stack, std::uint32_t cascade, glm::vec3 p0) {
  using namespace gpu_shared;
  light_detail::LightCacheShader sh{stack.pageTables.data(),   stack.distanceAtlas->data(),
                                    stack.albedoAtlas->data(), stack.emissionAtlas->data(),
                                    stack.params.data(),       nullptr};
  const CascadeTraceParams& cp = stack.params[cascade];
  const glm::vec3 p = (p0 - glm::vec3(cp.offsetScale)) / cp.offsetScale.w;
  const glm::ivec3 page = sh.sdfPageOf(p);
  const std::uint32_t entry = stack.pageTables[sh.sdfPageIndex(page, cp.toroidal)];
  if ((entry & kPageResidentBit) == 0u) return -1;
  const glm::ivec3 cellXyz =
      glm::clamp(glm::ivec3(glm::floor(p - glm::vec3(page) * 8.0f)), glm::ivec3(0), glm::ivec3(7));
  return std::int64_t(entry & kPagePayloadMask) * kBrickMaterialCount +
         (cellXyz.x + 8 * (cellXyz.y + 8 * cellXyz.z));
}

LightCacheWork lightCacheWork(const CascadeStackImage& stack,
                              std::span<const gpu_shared::GpuLight> lights,
                              const LightCacheSettings& settings) {
  using gpu_shared::kBrickMaterialCount;
  const std::uint32_t cascades = std::uint32_t(stack.params.size());
  const std::vector<std::uint32_t> pages = lightDirtyPages(nullptr, stack, true);
  const gpu_shared::LightCachePushConstants pc =
      lightCachePushConstants(settings, std::uint32_t(pages.size()), std::uint32_t(lights.size()),
                              cascades, gpu_shared::GpuSky{}, stack.voxelSize0);
  const light_detail::LightCacheShader shader{
      stack.pageTables.data(),     stack.distanceAtlas->data(), stack.albedoAtlas->data(),
      stack.emissionAtlas->data(), stack.params.data(),         lights.data()};
  // Per page: its surface cells' steps in cell order, and its rays.
  struct PageWork {
    std::vector<std::uint32_t> steps;
    std::uint64_t rays = 0, blocked = 0;
  };
  std::vector<PageWork> work(pages.size());
  tbb::parallel_for(std::size_t(0), pages.size(), [&](std::size_t i) {
    light_detail::LightCacheShader sh = shader;
    const std::uint32_t global = pages[i];
    const std::uint32_t cascade = global / gpu_shared::kCascadePageCount;
    const std::uint32_t slot = stack.pageTables[global] & gpu_shared::kPagePayloadMask;
    const glm::ivec3 page =
        sh.lightPageOfEntry(global % gpu_shared::kCascadePageCount, stack.params[cascade].toroidal);
    for (std::uint32_t cell = 0; cell < kBrickMaterialCount; ++cell) {
      if (lights.empty() || !sh.lightCellIsSurface(cascade, page, cell)) continue;
      sh.marches = sh.marchSteps = sh.blockedMarches = 0;
      sh.lightCacheCellRadiance(cascade, page, slot, cell, pc.counts.y, pc.params.x, pc.counts.w,
                                pc.params.y, pc.counts.z);
      work[i].steps.push_back(sh.marchSteps);
      work[i].rays += sh.marches;
      work[i].blocked += sh.blockedMarches;
    }
  });
  LightCacheWork out;
  out.pages = pages.size();
  out.surfaceCellsByCascade.assign(cascades, 0);
  out.stepsByCascade.assign(cascades, 0);
  // Σ over consecutive groups of 32 of the group's largest value.
  auto warpSteps = [](const std::vector<std::uint32_t>& v, std::size_t first, std::size_t stride,
                      std::size_t end) {
    std::uint64_t sum = 0;
    for (std::size_t base = first; base < end; base += stride) {
      std::uint32_t longest = 0;
      for (std::size_t k = base; k < std::min(base + 32, end); ++k)
        longest = std::max(longest, v[k]);
      sum += longest;
    }
    return sum;
  };
  std::vector<std::uint32_t> all;
  for (std::size_t i = 0; i < pages.size(); ++i) {
    const std::vector<std::uint32_t>& st = work[i].steps;
    const std::uint32_t cascade = pages[i] / gpu_shared::kCascadePageCount;
    out.surfaceCells += st.size();
    out.surfaceCellsByCascade[cascade] += st.size();
    out.shadowRays += work[i].rays;
    out.blockedRays += work[i].blocked;
    for (std::uint32_t v : st) out.stepsByCascade[cascade] += v;
    // light_cache.comp: lane l of 64 takes compacted cells l, l + 64, ...: warp w the 32 from
    // 32 w in each round of 64.
    out.warpStepsPerPage += warpSteps(st, 0, 64, st.size()) + warpSteps(st, 32, 64, st.size());
    all.insert(all.end(), st.begin(), st.end());
  }
  out.warpStepsOneList = warpSteps(all, 0, 32, all.size());
  for (std::uint64_t s : out.stepsByCascade) out.steps += s;
  out.warpStepsFloor = (out.steps + 31) / 32;
  if (!all.empty()) {
    std::sort(all.begin(), all.end());
    out.maxCellSteps = all.back();
    out.medianCellSteps = all[all.size() / 2];
    out.p99CellSteps = all[std::min(all.size() - 1, all.size() * 99 / 100)];
  }
  return out;
}

std::vector<std::uint32_t> lightDirtyPages(const CascadeStackImage* previous,
                                           const CascadeStackImage& current, bool lightsChanged) {
  using gpu_shared::kCascadePageCount;
  const std::uint32_t cascades = std::uint32_t(current.params.size());
  const bool all = lightsChanged || previous == nullptr ||
                   previous->params.size() != current.params.size() ||
                   previous->pageTables.size() != current.pageTables.size() ||
                   previous->voxelSize0 != current.voxelSize0;
  std::vector<std::uint32_t> out;
  for (std::uint32_t c = 0; c < cascades; ++c) {
    // A scrolled cascade maps entries to new bricks; compare bricks only then (cheap otherwise).
    const bool scrolled =
        !all && (previous->params[c].toroidal != current.params[c].toroidal ||
                 previous->params[c].offsetScale != current.params[c].offsetScale ||
                 previous->cascade0MinWorld != current.cascade0MinWorld);
    for (std::uint32_t e = 0; e < kCascadePageCount; ++e) {
      const std::uint32_t global = c * kCascadePageCount + e;
      const std::uint32_t entry = current.pageTables[global];
      if ((entry & gpu_shared::kPageResidentBit) == 0u) continue;
      if (all || entry != previous->pageTables[global] ||
          (scrolled &&
           light_detail::entryBrick(*previous, c, e) != light_detail::entryBrick(current, c, e)))
        out.push_back(global);
    }
  }
  return out;
}

glm::vec3 skyRadianceCpu(const gpu_shared::GpuSky& sky, glm::vec3 dir) {
  return light_detail::LightCacheShader{}.skyRadiance(sky, dir);
}

gpu_shared::LightCachePushConstants lightCachePushConstants(
    const LightCacheSettings& settings, std::uint32_t pageCount, std::uint32_t lightCount,
    std::uint32_t cascadeCount, const gpu_shared::GpuSky& sky, double voxelSize0) {
  assert(lightCount <= gpu_shared::kMaxLights);
  gpu_shared::LightCachePushConstants pc{};
  pc.counts = glm::uvec4(pageCount, lightCount, cascadeCount, settings.maxShadowSteps);
  pc.params = glm::vec4(float(voxelSize0), settings.hitEpsilon, 0.0f, 0.0f);
  pc.sky = sky;
  return pc;
}

void LightCacheCpu::update(const CascadeStackImage& stack,
                           std::span<const gpu_shared::GpuLight> lights,
                           const gpu_shared::GpuSky& sky, std::span<const std::uint32_t> dirtyPages,
                           double voxelSize0) {
  if (radiance_.size() < stack.albedoAtlas->size()) radiance_.resize(stack.albedoAtlas->size(), 0u);
  pagesRelit_ = std::uint32_t(dirtyPages.size());
  if (dirtyPages.empty()) return;
  const gpu_shared::LightCachePushConstants pc = lightCachePushConstants(
      settings_, std::uint32_t(dirtyPages.size()), std::uint32_t(lights.size()),
      std::uint32_t(stack.params.size()), sky, voxelSize0);
  light_detail::LightCacheShader shader{stack.pageTables.data(),   stack.distanceAtlas->data(),
                                        stack.albedoAtlas->data(), stack.emissionAtlas->data(),
                                        stack.params.data(),       lights.data()};
  const std::size_t cells = dirtyPages.size() * gpu_shared::kBrickMaterialCount;
  // Each listed page owns its slot's 512 words, so parallel writes never overlap (a page listed
  // twice writes the same values twice).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells, 64),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      light_detail::LightCacheShader local = shader;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        std::uint32_t index = 0, value = 0;
                        if (local.relightCell(dirtyPages[i / gpu_shared::kBrickMaterialCount],
                                              std::uint32_t(i % gpu_shared::kBrickMaterialCount),
                                              pc, index, value))
                          radiance_[index] = value;
                      }
                    });
}

}  // namespace sdfstream
