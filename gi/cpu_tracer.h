// CPU reference of the trace pass: the very same math as trace_rays.comp (both include
// shaders/sdf_trace.glsl), used by tests to check the GPU texel by texel and as a fallback.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "shaders/shared/sdf_layout.h"
#include "streaming/cascade.h"
#include "streaming/cascade_stack.h"

namespace sdfstream {

struct TraceSettings {
  std::uint32_t maxSteps = 256;    // iteration cap per ray
  float hitEpsilon = 0.02f;        // voxels; a distance sample below this is a hit
  std::uint32_t firstCascade = 0;  // stack traversal: start here, as a probe of that cascade
  // Stack traversal: step as sampling's visibility tests do (sdfVisibilitySteps: hit or miss
  // only, surfaces far from tMax count a quarter voxel thicker) instead of exactly. CPU only:
  // GpuStackTracer traces exactly and rejects it.
  bool visibilityRule = false;
  // Stack traversal: descend into a finer cascade where the ray enters its window, as camera rays
  // do (sdfTraceStack); off, as probe rays (sdfTraceStackFrom). CPU only, like visibilityRule.
  bool descend = false;
};

// Traces rays (cascade voxel units) against the cascade. Thread-safe; parallel over rays (TBB).
std::vector<gpu_shared::TraceHit> traceRaysCpu(const CascadeImage& cascade,
                                               std::span<const gpu_shared::TraceRay> rays,
                                               const TraceSettings& settings);

// Where a trace's steps went, by kind (sdf_trace.glsl, kSdfStep*): samples of a brick within a
// voxel of a surface, farther inside the band, clamped at its edge; leaps across empty pages;
// stops at missing pages. The kinds sum to the rays' TraceHit::steps.
struct TraceStepKinds {
  static constexpr std::size_t kKinds = 5;
  std::array<std::uint64_t, kKinds> steps{};
};

// Traces rays given in cascade-0 voxels through the whole stack (sdfTraceStack). Hit t is in
// cascade-0 voxels; the hit's cascade is in flags >> kHitCascadeShift. stepKinds, where given,
// gets each step added to its kind.
std::vector<gpu_shared::TraceHit> traceStackCpu(const CascadeStackImage& stack,
                                                std::span<const gpu_shared::TraceRay> rays,
                                                const TraceSettings& settings,
                                                TraceStepKinds* stepKinds = nullptr);

}  // namespace sdfstream
