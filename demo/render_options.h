// What every rendering command (render, demo, fly, stress) is told about its pictures: GI on or
// off, the GI frames before a still image, the GI renderer's settings, the lights and the
// exposure. The command line's shared flags (--gi, --gi-frames, --probe-rays, --probe-budget,
// --sun, --sky, --exposure, --direct) fill it in tools/render_args.h.
#pragma once

#include <cstdint>

#include "demo/gi_shading.h"
#include "gpu/context.h"
#include "world/scene_lights.h"

namespace sdfstream {

struct RenderOptions {
  bool gi = true;
  int giFrames = 24;           // GI frames before a still image (camera fixed)
  GiRendererOptions renderer;  // probe settings (--probe-rays), shading (--direct)
  SceneLights lights;          // --sun, --sky
  bool packLights = true;      // a pack's own lights replace `lights` (false: --sun was given)
  float exposureStops = 0.0f;  // --exposure
};

// settings.probes.rayBudget == kProbeBudgetOfDevice: the streamed commands (fly, stress) choose
// the budget by device, see resolveProbeBudget.
constexpr std::uint32_t kProbeBudgetOfDevice = 0;

// Replaces kProbeBudgetOfDevice by the budget for `context`: on a CPU Vulkan device (lavapipe) a
// full probe update of six cascades takes ~16 s a frame, so 65536 rays keep a fly-through to
// about a second a frame there (updates rotate through the probes, nearest and in view first);
// 2^21 on a real GPU. context == nullptr counts as a GPU (the CPU reference has no probes).
inline void resolveProbeBudget(GiSettings& settings, const gpu::Context* context) {
  if (settings.probes.rayBudget != kProbeBudgetOfDevice) return;
  settings.probes.rayBudget = context && context->isSoftware() ? 1u << 16 : 1u << 21;
}

}  // namespace sdfstream
