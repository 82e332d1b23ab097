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
// the budget by device, see resolveDeviceBudgets.
constexpr std::uint32_t kProbeBudgetOfDevice = 0;
// settings.light.relightPageBudget == kRelightBudgetOfDevice: the same for the light cache.
constexpr std::uint32_t kRelightBudgetOfDevice = 0;

// Replaces the *OfDevice budgets by those for `context` (nullptr counts as a GPU: the CPU
// reference has no probes and no light cache):
//  - probe rays: on a CPU Vulkan device (lavapipe) a full probe update of six cascades takes
//    ~16 s a frame, so 65536 rays keep a fly-through to about a second a frame there (updates
//    rotate through the probes, nearest and in view first); kDefaultProbeRayBudget on a GPU;
//  - light-cache pages relit per frame: a sun that moves every frame relights every resident page
//    (4,000-8,000 in a fly-through) each frame without a budget, 2.6 s a frame on lavapipe; 64
//    pages there, 256 on a GPU (0.23 ms a frame for Sponza on an H200, every page relit within
//    56 frames; LightRelightQueue: the longest out of date first). stress keeps relighting
//    every page, so its light-cache cost is the whole cost.
inline void resolveDeviceBudgets(GiSettings& settings, const gpu::Context* context) {
  const bool software = context && context->isSoftware();
  if (settings.probes.rayBudget == kProbeBudgetOfDevice)
    settings.probes.rayBudget = software ? 1u << 16 : probe::kDefaultProbeRayBudget;
  if (settings.light.relightPageBudget == kRelightBudgetOfDevice)
    settings.light.relightPageBudget = software ? 64u : 256u;
}

}  // namespace sdfstream
