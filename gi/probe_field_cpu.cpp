#include "gi/probe_field_cpu.h"

#include <array>
#include <atomic>
#include <bit>
#include <cassert>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include <glm/gtc/packing.hpp>
#include <glm/integer.hpp>

#include "gi/probe_upsample.h"
#include "shaders/shared/color_codec.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream::probe {
namespace field_detail {
using namespace glm;
using namespace gpu_shared;
using gpu_shared::ProbeVolume;

inline float uintBitsToFloat(std::uint32_t u) { return glm::uintBitsToFloat(u); }
inline std::uint32_t floatBitsToUint(float f) { return glm::floatBitsToUint(f); }

// The GLSL becomes member functions; the macros read and write this object's pointers (the
// CascadeStackImage and the ProbeFieldCpu's storage).
struct FieldPasses {
  const std::uint32_t* pageTable = nullptr;
  const std::uint32_t* distanceAtlas = nullptr;
  const std::uint32_t* albedoAtlas = nullptr;
  const std::uint32_t* emissionAtlas = nullptr;
  const CascadeTraceParams* cascades = nullptr;
  const std::uint32_t* lightRadiance = nullptr;
  const ProbeVolume* volumes = nullptr;
  const glm::vec4* rayPattern = nullptr;
  const std::uint32_t* pageChanged = nullptr;
  glm::vec4* irradiance = nullptr;
  glm::vec2* depth = nullptr;
  glm::vec4* rays = nullptr;
  glm::vec4* rayDirs = nullptr;
  glm::vec4* probeData = nullptr;
  glm::uvec4* history = nullptr;
  glm::uvec2* hitCache = nullptr;
  std::uint32_t* bounceCells = nullptr;
  glm::uvec4* bounceWork = nullptr;
  std::uint32_t* updateList = nullptr;
  std::uint32_t* stats = nullptr;
  std::uint32_t* dispatchArgs = nullptr;  // unused on the CPU (it loops to the list's length)

  static std::uint32_t atomicAdd(std::uint32_t& x, std::uint32_t v) {
    return std::atomic_ref<std::uint32_t>(x).fetch_add(v);
  }
  static std::uint32_t atomicCompSwap(std::uint32_t& x, std::uint32_t compare, std::uint32_t data) {
    std::atomic_ref<std::uint32_t>(x).compare_exchange_strong(compare, data);
    return compare;  // the value x held, as GLSL's atomicCompSwap returns
  }
  // The stack image's buffers (every pass reads them).
  explicit FieldPasses(const CascadeStackImage& stack)
      : pageTable(stack.pageTables.data()),
        distanceAtlas(stack.distanceAtlas->data()),
        albedoAtlas(stack.albedoAtlas->data()),
        emissionAtlas(stack.emissionAtlas->data()),
        cascades(stack.params.data()) {}
  FieldPasses() = default;

#include "shaders/probe_field_storage.glsl"
#undef SDF_PAGE
#undef SDF_DIST_WORD
#undef SDF_ALBEDO
#undef SDF_EMISSION
#undef SDF_CASCADE
#undef PROBE_IRRADIANCE
#undef PROBE_DEPTH
#undef PROBE_RAY
#undef PROBE_RAY_DIR
#undef PROBE_RAY_STORED
#undef PROBE_RAY_PATTERN
#undef PROBE_DISPATCH_ARGS
#undef PROBE_VOLUME
#undef PROBE_DATA
#undef PROBE_HISTORY
#undef PROBE_CACHE
#undef PROBE_ROTATION
#undef PROBE_PAGE_CHANGED
#undef LIGHT_RADIANCE
#undef LIGHT_BOUNCE_E
#undef LIGHT_BOUNCE_WORD
#undef LIGHT_BOUNCE_CLAIM
#undef PROBE_BOUNCE_WORK
#undef PROBE_APPEND
#undef PROBE_LIST
#undef PROBE_STAT
#undef PROBE_STAT_ADD
#undef PROBE_STAT_COUNT
};
}  // namespace field_detail

std::size_t ProbeFieldSizes::bytes() const {
  return probes * (16 + 16) + irradianceTexels * 16 + depthTexels * 8 + rays * 32 +
         cacheEntries * 8 + bounceWork * 16;
}

ProbeFieldSizes probeFieldSizes(const ProbeFieldSettings& s, std::uint32_t cascades) {
  ProbeFieldSizes z;
  z.probes = std::size_t(cascades) * s.probesPerVolume();
  z.irradianceTexels =
      z.probes * gpu_shared::kProbeIrradianceTexels * gpu_shared::kProbeIrradianceTexels;
  z.depthTexels = z.probes * gpu_shared::kProbeDepthTexels * gpu_shared::kProbeDepthTexels;
  z.rays = std::size_t(s.listCapacity(cascades)) * s.raysPerProbe;
  z.cacheEntries = s.hitCache ? z.probes * s.cacheRotations * s.raysPerProbe : 1;
  z.bounceWork = s.bounceCellUpdates > 0 ? 2 * z.rays : 1;
  return z;
}

ProbeFieldStats decodeStats(std::span<const std::uint32_t> raw) {
  using namespace gpu_shared;
  assert(raw.size() >= kProbeStatCount);
  ProbeFieldStats s;
  for (std::uint32_t c = 0; c < kProbeClassCount; ++c)
    s.classCounts[c] = raw[kProbeStatClassCounts + c];
  s.probesUpdated = raw[kProbeStatListCount];
  s.raysTraced = raw[kProbeStatRaysTraced];
  s.raysCached = raw[kProbeStatRaysCached];
  s.steps = raw[kProbeStatSteps];
  for (int i = 0; i < 4; ++i) s.states[i] = raw[kProbeStatStates + i];
  s.cacheInvalidated = raw[kProbeStatCacheInvalidated];
  s.objectRays = raw[kProbeStatObjectRays];
  s.objectHits = raw[kProbeStatObjectHits];
  s.objectSteps = raw[kProbeStatObjectSteps];
  s.bounceCells = raw[kProbeStatBounceCells];
  s.bounceRays = raw[kProbeStatBounceRays];
  s.bounceOwn = raw[kProbeStatBounceOwn];
  return s;
}

ProbeFieldCpu::ProbeFieldCpu(const ProbeFieldSettings& settings, std::uint32_t cascades)
    : settings_(settings), cascades_(cascades), builder_(settings) {
  reset();
}

void ProbeFieldCpu::reset() {
  const ProbeFieldSizes z = probeFieldSizes(settings_, cascades_);
  data_.assign(z.probes, glm::vec4(0.0f));
  history_.assign(z.probes, glm::uvec4(0u));
  irradiance_.assign(z.irradianceTexels, glm::vec4(0.0f));
  depth_.assign(z.depthTexels, glm::vec2(0.0f));
  rays_.assign(z.rays, glm::vec4(0.0f));
  rayDirs_.assign(z.rays, glm::vec4(0.0f));
  cache_.assign(z.cacheEntries, glm::uvec2(0u));
  bounceCells_.clear();
  bounceWork_.assign(z.bounceWork, glm::uvec4(0u));
  list_.assign(settings_.listCapacity(cascades_), 0u);
  rawStats_.assign(gpu_shared::kProbeStatCount, 0u);
  builder_.reset();
}

void ProbeFieldCpu::update(const CascadeStackImage& stack, std::span<const std::uint32_t> light,
                           const ProbeFrameInputs& inputs, std::uint64_t frame) {
  assert(stack.params.size() == cascades_);
  frame_ = builder_.build(stack, inputs, frame);
  const gpu_shared::ProbeFrame& f = frame_.constants;
  std::fill(rawStats_.begin(), rawStats_.end(), 0u);
  field_detail::FieldPasses base(stack);
  base.lightRadiance = light.data();
  base.volumes = frame_.volumes.data();
  base.rayPattern = frame_.rayPattern->data();
  base.pageChanged = frame_.pageChanged.data();
  base.irradiance = irradiance_.data();
  base.depth = depth_.data();
  base.rays = rays_.data();
  base.rayDirs = rayDirs_.data();
  base.probeData = data_.data();
  base.history = history_.data();
  base.hitCache = cache_.data();
  // The bounce cells grow with the atlas (the light cache holds one word per material voxel),
  // emptied as the GPU field's are (ProbeField::growBounceCells).
  if (settings_.bounceCellUpdates > 0 && bounceCells_.size() < 2 * light.size())
    bounceCells_.assign(2 * light.size(), 0u);
  base.bounceCells = bounceCells_.data();
  base.bounceWork = bounceWork_.data();
  base.updateList = list_.data();
  base.stats = rawStats_.data();
  const std::uint32_t probes = std::uint32_t(data_.size());

  // Classify (probe_classify.comp): each probe touches only its own data.
  tbb::parallel_for(std::uint32_t(0), probes, [&](std::uint32_t g) {
    auto local = base;
    local.probeClassifyPass(f, g);
  });
  // Hit-cache check (probe_cache_check.comp): each entry touches only itself.
  if (checksHitCache(f))
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cache_.size(), 4096), [&](const auto& r) {
      auto local = base;
      for (std::size_t i = r.begin(); i < r.end(); ++i)
        local.probeCacheCheckPass(f, std::uint32_t(i));
    });
  // Select (probe_select.comp): count, then emit. Serial emit in probe order: the GPU's list
  // order differs, but each probe's results do not depend on its list position.
  tbb::parallel_for(std::uint32_t(0), probes, [&](std::uint32_t g) {
    auto local = base;
    local.probeSelectPass(f, g, gpu_shared::kProbeSelectModeCount);
  });
  for (std::uint32_t g = 0; g < probes; ++g)
    base.probeSelectPass(f, g, gpu_shared::kProbeSelectModeEmit);
  const std::uint32_t listed = std::min(rawStats_[gpu_shared::kProbeStatListCount], f.selection.y);
  const std::uint32_t n = settings_.raysPerProbe;
  // Trace + shade (probe_trace.comp).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, std::size_t(listed) * n, 64), [&](auto r) {
    auto local = base;
    for (std::size_t i = r.begin(); i < r.end(); ++i)
      local.probeTracePass(f, std::uint32_t(i / n), std::uint32_t(i % n));
  });
  // Bounce cells, then the rays that waited for them, then those that look up their own
  // (probe_bounce.comp, three dispatches).
  if (f.bounce.y > 0) {
    const std::uint32_t cells = rawStats_[gpu_shared::kProbeStatBounceCells];
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, cells, 64), [&](auto r) {
      auto local = base;
      for (std::uint32_t i = r.begin(); i < r.end(); ++i) local.probeBounceCellPass(f, i);
    });
    const std::uint32_t waiting = rawStats_[gpu_shared::kProbeStatBounceRays];
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, waiting, 64), [&](auto r) {
      auto local = base;
      for (std::uint32_t i = r.begin(); i < r.end(); ++i) local.probeBounceRayPass(f, i);
    });
    const std::uint32_t own = rawStats_[gpu_shared::kProbeStatBounceOwn];
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, own, 64), [&](auto r) {
      auto local = base;
      for (std::uint32_t i = r.begin(); i < r.end(); ++i) local.probeBounceOwnPass(f, i);
    });
  }
  // Blend: interior texels and their border copies (probe_blend.comp).
  tbb::parallel_for(std::uint32_t(0), listed, [&](std::uint32_t l) {
    auto local = base;
    for (std::uint32_t t = 0; t < gpu_shared::kProbeBlendTexelsPerProbe; ++t)
      local.probeBlendPass(f, l, t);
  });
  stats_ = decodeStats(rawStats_);
}

namespace {
// probe_sample.comp: a query whose normal is zero has no surface.
bool hasSurface(const gpu_shared::ProbeQuery& q) {
  return glm::dot(glm::vec3(q.normal), glm::vec3(q.normal)) > 0.0f;
}

// The passes' view of a field for sampling: the stack and the probes' volumes, texels and data.
// Sampling only reads; the pointers are non-const because the pass structs also write.
field_detail::FieldPasses samplingPasses(const CascadeStackImage& stack,
                                         const std::vector<gpu_shared::ProbeVolume>& volumes,
                                         const std::vector<glm::vec4>& irradiance,
                                         const std::vector<glm::vec2>& depth,
                                         const std::vector<glm::vec4>& data) {
  field_detail::FieldPasses base(stack);
  base.volumes = volumes.data();
  base.irradiance = const_cast<glm::vec4*>(irradiance.data());
  base.depth = const_cast<glm::vec2*>(depth.data());
  base.probeData = const_cast<glm::vec4*>(data.data());
  return base;
}
}  // namespace

std::vector<glm::vec3> ProbeFieldCpu::sample(const CascadeStackImage& stack,
                                             std::span<const gpu_shared::ProbeQuery> queries,
                                             SampleTraces traces, SampleCounts* counts) const {
  if (settings_.nearFieldRays > 0)
    throw std::logic_error("ProbeFieldCpu::sample: the near field is on; use sampleNearField");
  const field_detail::FieldPasses base =
      samplingPasses(stack, frame_.volumes, irradiance_, depth_, data_);
  std::vector<glm::vec3> out(queries.size());
  std::atomic<std::uint64_t> cages = 0, sharedCages = 0, traced = 0, own = 0;
  if (traces == SampleTraces::AsSettings)
    traces = settings_.shareSdfTests ? SampleTraces::GroupsShareTraces : SampleTraces::PerQuery;
  if (traces == SampleTraces::PerQuery) {
    if (counts) *counts = {};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 64), [&](auto r) {
      auto local = base;
      for (std::size_t i = r.begin(); i < r.end(); ++i)
        out[i] = !hasSurface(queries[i])
                     ? glm::vec3(0.0f)
                     : local.probeFieldIrradiance(frame_.constants, glm::vec3(queries[i].position),
                                                  glm::vec3(queries[i].normal),
                                                  glm::vec3(queries[i].view), true,
                                                  int(queries[i].position.w) - 1);
    });
    return out;
  }
  // probe_sample.comp: groups of kProbeSampleShareLanes consecutive queries share the SDF tests
  // of a cage they all plan (probeGroupSharesCage), each lane tracing its share of the union
  // towards its own receiver.
  constexpr std::size_t kLanes = gpu_shared::kProbeSampleShareLanes;
  const std::size_t groups = (queries.size() + kLanes - 1) / kLanes;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, groups, 16), [&](auto r) {
    auto local = base;
    const gpu_shared::ProbeFrame& f = frame_.constants;
    for (std::size_t group = r.begin(); group < r.end(); ++group) {
      const std::size_t first = group * kLanes;
      const std::size_t lanes = std::min(kLanes, queries.size() - first);
      std::array<field_detail::FieldPasses::ProbeFieldPlan, kLanes> plans{};
      for (std::size_t l = 0; l < lanes; ++l) {
        const gpu_shared::ProbeQuery& q = queries[first + l];
        if (hasSurface(q))  // else no cage: the lane samples nothing and shares nothing
          plans[l] = local.probeFieldPlan(f, glm::vec3(q.position), glm::vec3(q.normal),
                                          glm::vec3(q.view), int(q.position.w) - 1);
      }
      std::array<std::array<std::uint32_t, 2>, kLanes> visible{};
      for (std::uint32_t i = 0; i < 2; ++i) {
        bool shares = lanes == kLanes;
        for (std::size_t l = 0; l < kLanes && shares; ++l)
          shares = i < plans[l].count &&
                   (l == 0 || local.probeGroupSharesCage(plans[0].cage[i], plans[l].cage[i]));
        std::uint32_t all = 0;
        if (shares)
          for (std::size_t l = 0; l < kLanes; ++l) all |= plans[l].cage[i].traceMask;
        std::uint32_t any = 0;
        for (std::size_t l = 0; l < lanes; ++l) {
          if (i >= plans[l].count) continue;
          const auto& cage = plans[l].cage[i];
          const std::uint32_t corners =
              shares ? local.probeGroupLaneCorners(all, std::uint32_t(l)) : cage.traceMask;
          visible[l][i] = local.probeCageTrace(f, cage, corners, cage.biased);
          any |= visible[l][i];
          cages += 1;
          sharedCages += shares ? 1 : 0;
          traced += std::uint64_t(std::popcount(corners));
          own += std::uint64_t(std::popcount(cage.traceMask));
        }
        if (shares)
          for (std::size_t l = 0; l < kLanes; ++l) visible[l][i] = any;
      }
      for (std::size_t l = 0; l < lanes; ++l) {
        const gpu_shared::ProbeQuery& q = queries[first + l];
        if (!hasSurface(q)) continue;
        out[first + l] =
            local.probeFieldFinish(f, plans[l], glm::vec3(q.position), glm::vec3(q.normal),
                                   glm::vec3(q.view), visible[l][0], visible[l][1]);
      }
    }
  });
  if (counts) *counts = {cages.load(), sharedCages.load(), traced.load(), own.load()};
  return out;
}

std::vector<glm::vec3> ProbeFieldCpu::sampleNearField(
    const CascadeStackImage& stack, std::span<const std::uint32_t> lightRadiance,
    std::span<const gpu_shared::ProbeQuery> queries) const {
  field_detail::FieldPasses base =
      samplingPasses(stack, frame_.volumes, irradiance_, depth_, data_);
  base.lightRadiance = lightRadiance.data();
  std::vector<glm::vec3> out(queries.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 16), [&](auto r) {
    auto local = base;
    for (std::size_t i = r.begin(); i < r.end(); ++i)
      out[i] = !hasSurface(queries[i]) ? glm::vec3(0.0f)
                                       : local.probeNearFieldIrradiance(
                                             frame_.constants, glm::vec3(queries[i].position),
                                             glm::vec3(queries[i].normal));
  });
  return out;
}

std::vector<glm::vec3> ProbeFieldCpu::sampleHalfResolution(
    const CascadeStackImage& stack, std::span<const gpu_shared::ProbeQuery> image,
    std::uint32_t width, std::uint32_t height, std::uint32_t blockSize) const {
  const HalfResolutionPlan plan = planHalfResolution(image, width, height, blockSize);
  const std::vector<glm::vec3> sampled = sample(stack, plan.queries);
  return upsampleHalfResolution(image, halfResolutionSamples(plan, sampled), width, height,
                                blockSize);
}

}  // namespace sdfstream::probe

namespace sdfstream::probe {

glm::vec3 ProbeFieldCpu::probePosition(std::uint32_t g) const {
  field_detail::FieldPasses base;
  const std::uint32_t per = settings_.probesPerVolume();
  const gpu_shared::ProbeVolume& v = frame_.volumes[g / per];
  return base.probeGridPosition(v, base.probeLogicalCoord(v, g % per)) + glm::vec3(data_[g]);
}

glm::vec2 ProbeFieldCpu::traceFresh(const CascadeStackImage& stack, std::uint32_t g,
                                    std::uint32_t slot, std::uint32_t ray) const {
  field_detail::FieldPasses base(stack);
  base.rayPattern = frame_.rayPattern->data();
  const std::uint32_t c = g / settings_.probesPerVolume();
  const glm::vec3 dir = base.probeRotationSlotDirection(slot, ray, settings_.raysPerProbe);
  const auto h = base.probeTraceFresh(frame_.constants, c, probePosition(g), dir);
  return glm::vec2(h.hit ? h.t0 : -1.0f, float(h.cascade));
}

}  // namespace sdfstream::probe
