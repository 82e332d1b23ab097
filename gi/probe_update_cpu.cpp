#include "gi/probe_update_cpu.h"

#include <cassert>

#include <tbb/parallel_for.h>

#include <glm/gtc/packing.hpp>

#include "gi/probe_math.h"
#include "shaders/shared/color_codec.h"

namespace sdfstream::probe {
namespace update_detail {
using namespace glm;
using namespace gpu_shared;
using gpu_shared::ProbeVolume;

// The GLSL functions become member functions; the macros read this object's pointers, which
// point at a CascadeStackImage and at the ProbeUpdateCpu's storage.
struct ProbeUpdater {
  const std::uint32_t* pageTable = nullptr;
  const std::uint32_t* distanceAtlas = nullptr;
  const std::uint32_t* albedoAtlas = nullptr;
  const std::uint32_t* emissionAtlas = nullptr;
  const CascadeTraceParams* cascades = nullptr;
  const glm::vec4* irradiance = nullptr;
  const glm::vec4* rays = nullptr;
  const glm::vec2* depthTexels = nullptr;

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#include "shaders/probe_math.glsl"
#include "shaders/sdf_trace.glsl"
#define PROBE_IRRADIANCE(i) irradiance[i]
#define PROBE_RAY(i) rays[i]
#define PROBE_DEPTH(i) depthTexels[i]
#include "shaders/probe_update.glsl"
#undef SDF_PAGE
#undef SDF_DIST_WORD
#undef SDF_ALBEDO
#undef SDF_EMISSION
#undef SDF_CASCADE
#undef PROBE_IRRADIANCE
#undef PROBE_RAY
#undef PROBE_DEPTH
};
}  // namespace update_detail

namespace {
constexpr std::uint32_t kIrrTile = gpu_shared::kProbeIrradianceTexels;
constexpr std::uint32_t kDepthTile = gpu_shared::kProbeDepthTexels;
constexpr std::uint32_t kB = gpu_shared::kProbeBorderTexels;
}  // namespace

std::size_t irradianceTexelCount(const ProbeVolumeSettings& s) {
  return std::size_t(s.probeCount()) * kIrrTile * kIrrTile;
}
std::size_t depthTexelCount(const ProbeVolumeSettings& s) {
  return std::size_t(s.probeCount()) * kDepthTile * kDepthTile;
}
std::size_t rayCount(const ProbeVolumeSettings& s) {
  return std::size_t(s.probeCount()) * s.raysPerProbe;
}

gpu_shared::ProbeVolume volumeParams(const ProbeVolumeSettings& s, std::uint64_t frame) {
  assert(s.grid.x > 0 && s.grid.y > 0 && s.grid.z > 0 && s.raysPerProbe > 0);
  const glm::mat3 r = randomRotation(s.rotationSeed * 0x9E3779B97F4A7C15ull + frame);
  gpu_shared::ProbeVolume v{};
  v.originSpacing = glm::vec4(s.origin, s.spacing);
  v.countsRays = glm::uvec4(s.grid, s.raysPerProbe);
  v.scroll = glm::ivec4(0, 0, 0, int(frame & 0x7fffffff));
  v.rayRotationCol0 = glm::vec4(r[0], 0.0f);
  v.rayRotationCol1 = glm::vec4(r[1], 0.0f);
  v.rayRotationCol2 = glm::vec4(r[2], 0.0f);
  v.blend = glm::vec4(s.irradianceHysteresis, s.depthHysteresis, s.maxDepth, s.irradianceGamma);
  v.visibility = glm::vec4(s.selfShadowBias, s.depthSharpness, s.backfaceDepthScale, s.minVariance);
  return v;
}

gpu_shared::ProbeUpdatePushConstants updatePushConstants(const ProbeVolumeSettings& s,
                                                         std::uint32_t cascadeCount,
                                                         bool firstUpdate) {
  gpu_shared::ProbeUpdatePushConstants pc{};
  pc.skyBounce = glm::vec4(s.skyRadiance, s.bounceGain);
  pc.counts = glm::uvec4(s.probeCount(), 0u, s.maxSteps, cascadeCount);
  pc.trace = glm::vec4(s.hitEpsilon, s.traceDistance, s.adaptiveHysteresis ? 1.0f : 0.0f,
                       firstUpdate ? 1.0f : 0.0f);
  pc.mode = glm::uvec4(0u);
  return pc;
}

glm::vec3 irradianceTexel(std::span<const glm::vec4> atlas, std::uint32_t probe, glm::uvec2 t,
                          float gamma) {
  const glm::vec4 s =
      atlas[std::size_t(probe) * kIrrTile * kIrrTile + (t.y + kB) * kIrrTile + (t.x + kB)];
  return decodeIrradiance(glm::vec3(s), gamma);
}

glm::vec3 meanIrradiance(std::span<const glm::vec4> atlas, std::uint32_t probe, float gamma) {
  constexpr std::uint32_t n = gpu_shared::kProbeIrradianceInterior;
  glm::vec3 sum(0.0f);
  for (std::uint32_t y = 0; y < n; ++y)
    for (std::uint32_t x = 0; x < n; ++x) sum += irradianceTexel(atlas, probe, {x, y}, gamma);
  return sum / float(n * n);
}

ProbeUpdateCpu::ProbeUpdateCpu(const ProbeVolumeSettings& settings) : settings_(settings) {
  reset();
  rays_.assign(rayCount(settings_), glm::vec4(0.0f));
}

void ProbeUpdateCpu::reset() {
  irradiance_.assign(irradianceTexelCount(settings_), glm::vec4(0.0f));
  depth_.assign(depthTexelCount(settings_), glm::vec2(0.0f));
  firstUpdate_ = true;
}

void ProbeUpdateCpu::update(const CascadeStackImage& stack, std::uint64_t frame) {
  const gpu_shared::ProbeVolume v = volumeParams(settings_, frame);
  const gpu_shared::ProbeUpdatePushConstants pc =
      updatePushConstants(settings_, std::uint32_t(stack.params.size()), firstUpdate_);
  update_detail::ProbeUpdater base;
  base.pageTable = stack.pageTables.data();
  base.distanceAtlas = stack.distanceAtlas->data();
  base.albedoAtlas = stack.albedoAtlas->data();
  base.emissionAtlas = stack.emissionAtlas->data();
  base.cascades = stack.params.data();
  base.irradiance = irradiance_.data();
  base.rays = rays_.data();

  // Trace + shade (probe_trace.comp): reads the current irradiance, writes rays_.
  const std::uint32_t n = settings_.raysPerProbe;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays_.size(), 64), [&](auto range) {
    auto local = base;
    for (std::size_t i = range.begin(); i < range.end(); ++i)
      rays_[i] = local.probeTraceRay(v, pc, std::uint32_t(i / n), std::uint32_t(i % n));
  });

  // Blend interior texels (probe_blend.comp, interior mode): each texel reads only itself.
  const bool adaptive = pc.trace.z != 0.0f;
  const bool first = pc.trace.w != 0.0f;
  constexpr std::uint32_t kIrrInterior = gpu_shared::kProbeIrradianceInterior;
  constexpr std::uint32_t kDepthInterior = gpu_shared::kProbeDepthInterior;
  tbb::parallel_for(std::uint32_t(0), settings_.probeCount(), [&](std::uint32_t probe) {
    auto local = base;
    for (std::uint32_t y = 0; y < kIrrInterior; ++y)
      for (std::uint32_t x = 0; x < kIrrInterior; ++x) {
        glm::vec4& s = irradiance_[local.probeIrradianceIndex(probe, {x + kB, y + kB})];
        s = local.probeBlendIrradianceTexel(v, probe, {x, y}, s, adaptive, first);
      }
    for (std::uint32_t y = 0; y < kDepthInterior; ++y)
      for (std::uint32_t x = 0; x < kDepthInterior; ++x) {
        glm::vec2& s = depth_[local.probeDepthIndex(probe, {x + kB, y + kB})];
        s = local.probeBlendDepthTexel(v, probe, {x, y}, s, first);
      }
    // Borders (probe_blend.comp, border mode).
    for (std::uint32_t y = 0; y < kIrrTile; ++y)
      for (std::uint32_t x = 0; x < kIrrTile; ++x) {
        const glm::uvec2 src = borderSource({x, y}, kIrrTile);
        if (src != glm::uvec2(x, y))
          irradiance_[local.probeIrradianceIndex(probe, {x, y})] =
              irradiance_[local.probeIrradianceIndex(probe, src)];
      }
    for (std::uint32_t y = 0; y < kDepthTile; ++y)
      for (std::uint32_t x = 0; x < kDepthTile; ++x) {
        const glm::uvec2 src = borderSource({x, y}, kDepthTile);
        if (src != glm::uvec2(x, y))
          depth_[local.probeDepthIndex(probe, {x, y})] = depth_[local.probeDepthIndex(probe, src)];
      }
  });
  firstUpdate_ = false;
}

std::vector<glm::vec3> sampleIrradianceCpu(const ProbeVolumeSettings& settings,
                                           std::span<const glm::vec4> irradiance,
                                           std::span<const glm::vec2> depth,
                                           std::span<const gpu_shared::ProbeQuery> queries) {
  assert(irradiance.size() == irradianceTexelCount(settings));
  assert(depth.size() == depthTexelCount(settings));
  const gpu_shared::ProbeVolume v = volumeParams(settings, 0);
  update_detail::ProbeUpdater base;
  base.irradiance = irradiance.data();
  base.depthTexels = depth.data();
  std::vector<glm::vec3> out(queries.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 256), [&](auto range) {
    auto local = base;
    for (std::size_t i = range.begin(); i < range.end(); ++i)
      out[i] = local.probeSampleVolume(v, glm::vec3(queries[i].position),
                                       glm::vec3(queries[i].normal), glm::vec3(queries[i].view));
  });
  return out;
}

}  // namespace sdfstream::probe
