#include "gi/scene_lights.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace sdfstream {

std::vector<gpu_shared::GpuLight> toGpu(const std::vector<SceneLight>& lights,
                                        const CascadeStackImage& stack) {
  if (lights.size() > gpu_shared::kMaxLights)
    throw std::invalid_argument("scene has " + std::to_string(lights.size()) + " lights; at most " +
                                std::to_string(gpu_shared::kMaxLights) + " are supported");
  std::vector<gpu_shared::GpuLight> out;
  out.reserve(lights.size());
  for (const SceneLight& l : lights) {
    gpu_shared::GpuLight g{};
    const glm::vec3 dir = glm::normalize(l.direction);
    float type = float(gpu_shared::kLightSun);
    glm::vec3 position(0.0f);
    glm::vec3 gpuDir = -dir;  // sun: towards the light
    if (l.type != SceneLight::Type::Sun) {
      position = stack.toStack(l.position);
      gpuDir = dir;
      type = float(l.type == SceneLight::Type::Point ? gpu_shared::kLightPoint
                                                     : gpu_shared::kLightSpot);
    }
    const float toRad = 3.14159265358979f / 180.0f;
    g.positionType = glm::vec4(position, type);
    g.direction = glm::vec4(gpuDir, std::cos(l.outerConeDegrees * toRad));
    g.colorIntensity = glm::vec4(l.color, l.intensity);
    g.shape = glm::vec4(std::cos(l.innerConeDegrees * toRad), l.range, l.shadowSharpness,
                        l.castsShadows ? 1.0f : 0.0f);
    out.push_back(g);
  }
  return out;
}

gpu_shared::GpuSky toGpu(const SceneSky& sky) {
  gpu_shared::GpuSky g{};
  g.zenith = glm::vec4(sky.zenith, 0.0f);
  g.horizon = glm::vec4(sky.horizon, 0.0f);
  return g;
}

}  // namespace sdfstream
