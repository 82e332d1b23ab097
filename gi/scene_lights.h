// The GPU form of a scene's lights and sky (world/scene_lights.h, world units): toGpu() turns
// them into the shared GPU structs of shaders/shared/light_layout.h for one cascade stack
// (positions become cascade-0 voxels).
#pragma once

#include <vector>

#include "shaders/shared/light_layout.h"
#include "streaming/cascade_stack.h"
#include "world/scene_lights.h"

namespace sdfstream {

// GPU form for `stack` (positions relative to cascade 0's minimum corner, in its voxels).
// Throws std::invalid_argument when there are more than kMaxLights lights.
std::vector<gpu_shared::GpuLight> toGpu(const std::vector<SceneLight>& lights,
                                        const CascadeStackImage& stack);
gpu_shared::GpuSky toGpu(const SceneSky& sky);

}  // namespace sdfstream
