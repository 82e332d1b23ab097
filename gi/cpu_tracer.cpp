#include "gi/cpu_tracer.h"

#include <array>
#include <mutex>

#include <tbb/parallel_for.h>

#include <glm/gtc/packing.hpp>

#include "shaders/shared/color_codec.h"

namespace sdfstream {
namespace cpu_trace_detail {
using namespace glm;
using namespace gpu_shared;

// The GLSL functions become member functions; the SDF_* macros read this object's spans.
struct CascadeTracer {
  const std::uint32_t* pageTable;
  const std::uint32_t* distanceAtlas;
  const std::uint32_t* albedoAtlas;
  const std::uint32_t* emissionAtlas;
  const CascadeTraceParams* cascades = nullptr;  // stack traversal only
  std::array<std::uint64_t, TraceStepKinds::kKinds> stepKinds{};  // SDF_COUNT_STEP's counts

#define SDF_COUNT_STEP(kind) (++stepKinds[kind])
#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#include "shaders/sdf_trace.glsl"
#undef SDF_PAGE
#undef SDF_DIST_WORD
#undef SDF_ALBEDO
#undef SDF_EMISSION
#undef SDF_CASCADE
#undef SDF_COUNT_STEP
  static_assert(kSdfStepKinds == TraceStepKinds::kKinds);

  // Mirrors main() of trace_rays.comp.
  TraceHit traceOne(const TraceRay& ray, const TracePushConstants& pc) {
    vec3 origin(ray.originTMin);
    vec3 dir(ray.dirTMax);
    SdfTraceResult r = sdfTrace(origin, dir, ray.originTMin.w, ray.dirTMax.w, pc.maxSteps,
                                pc.hitEpsilon, pc.toroidalOffset);
    TraceHit h{};
    h.steps = r.steps;
    h.flags = (r.hit ? kHitFlagHit : 0u) | (r.ranOutOfSteps ? kHitFlagRanOutOfSteps : 0u) |
              (r.missingData ? kHitFlagMissingData : 0u);
    if (r.hit) {
      vec3 n = sdfNormal(r.position, pc.toroidalOffset);
      h.normalT = vec4(n, r.t);
      h.albedo = albedoAtlas[r.slot * kBrickMaterialCount + r.cell];
      h.emission = emissionAtlas[r.slot * kBrickMaterialCount + r.cell];
    } else {
      h.normalT = vec4(0.0f, 0.0f, 0.0f, -1.0f);
    }
    return h;
  }

  // Mirrors main() of trace_stack.comp (with the exact rule; the visibility rule is sampling's).
  TraceHit traceStackOne(const TraceRay& ray, const TraceStackPushConstants& pc,
                         bool visibilityRule, bool descend) {
    const SdfStepRule rule =
        visibilityRule ? sdfVisibilitySteps(pc.hitEpsilon) : sdfExactSteps(pc.hitEpsilon);
    SdfStackResult s =
        sdfTraceStackWith(vec3(ray.originTMin), vec3(ray.dirTMax), ray.originTMin.w, ray.dirTMax.w,
                          pc.maxSteps, rule, pc.firstCascade, pc.cascadeCount, descend);
    TraceHit h{};
    h.steps = s.steps;
    h.flags = (s.r.hit ? kHitFlagHit : 0u) | (s.r.ranOutOfSteps ? kHitFlagRanOutOfSteps : 0u) |
              (s.r.missingData ? kHitFlagMissingData : 0u) | (s.fellBack ? kHitFlagFellBack : 0u) |
              (s.cascade << kHitCascadeShift);
    if (s.r.hit) {
      vec3 n = sdfNormal(s.r.position, cascades[s.cascade].toroidal);
      h.normalT = vec4(n, s.t0);
      h.albedo = albedoAtlas[s.r.slot * kBrickMaterialCount + s.r.cell];
      h.emission = emissionAtlas[s.r.slot * kBrickMaterialCount + s.r.cell];
    } else {
      h.normalT = vec4(0.0f, 0.0f, 0.0f, -1.0f);
    }
    return h;
  }
};
}  // namespace cpu_trace_detail

std::vector<gpu_shared::TraceHit> traceStackCpu(const CascadeStackImage& stack,
                                                std::span<const gpu_shared::TraceRay> rays,
                                                const TraceSettings& settings,
                                                TraceStepKinds* stepKinds) {
  cpu_trace_detail::CascadeTracer tracer{stack.pageTables.data(), stack.distanceAtlas->data(),
                                         stack.albedoAtlas->data(), stack.emissionAtlas->data(),
                                         stack.params.data()};
  gpu_shared::TraceStackPushConstants pc{};
  pc.rayCount = std::uint32_t(rays.size());
  pc.maxSteps = settings.maxSteps;
  pc.hitEpsilon = settings.hitEpsilon;
  pc.cascadeCount = std::uint32_t(stack.params.size());
  pc.firstCascade = settings.firstCascade;
  std::vector<gpu_shared::TraceHit> hits(rays.size());
  std::mutex countsMutex;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](auto range) {
    auto local = tracer;
    for (std::size_t i = range.begin(); i < range.end(); ++i)
      hits[i] = local.traceStackOne(rays[i], pc, settings.visibilityRule, settings.descend);
    if (!stepKinds) return;
    std::lock_guard lock(countsMutex);
    for (std::size_t k = 0; k < local.stepKinds.size(); ++k)
      stepKinds->steps[k] += local.stepKinds[k];
  });
  return hits;
}

std::vector<gpu_shared::TraceHit> traceRaysCpu(const CascadeImage& cascade,
                                               std::span<const gpu_shared::TraceRay> rays,
                                               const TraceSettings& settings) {
  cpu_trace_detail::CascadeTracer tracer{cascade.pageTable.data(), cascade.distanceAtlas.data(),
                                         cascade.albedoAtlas.data(), cascade.emissionAtlas.data()};
  gpu_shared::TracePushConstants pc{};
  pc.toroidalOffset = cascade.toroidalOffset();
  pc.rayCount = std::uint32_t(rays.size());
  pc.maxSteps = settings.maxSteps;
  pc.hitEpsilon = settings.hitEpsilon;
  std::vector<gpu_shared::TraceHit> hits(rays.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](auto range) {
    auto local = tracer;
    for (std::size_t i = range.begin(); i < range.end(); ++i) hits[i] = local.traceOne(rays[i], pc);
  });
  return hits;
}

}  // namespace sdfstream
