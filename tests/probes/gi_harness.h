// The probe field and light cache driven together on the GPU and on the CPU reference, for the
// probe tests: one step() runs the light cache (dirty pages) and one probe field frame on both.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "gi/gpu_stack_scene.h"
#include "gi/light_cache.h"
#include "gi/probe_field.h"
#include "gi/probe_field_cpu.h"
#include "gi/scene_lights.h"
#include "gpu/context.h"

namespace sdfstream::test {

// One sun of `intensity` shining along `direction` (normalised here), in the stack's units.
inline std::vector<gpu_shared::GpuLight> sunLights(const CascadeStackImage& img,
                                                   glm::vec3 direction, float intensity) {
  sdfstream::SceneLight sun;
  sun.direction = glm::normalize(direction);
  sun.intensity = intensity;
  return sdfstream::toGpu(std::vector<sdfstream::SceneLight>{sun}, img);
}

struct GiHarness {
  bool runCpu = true, runGpu = true;
  probe::ProbeFieldSettings settings;
  std::unique_ptr<GpuStackScene> scene;
  std::unique_ptr<LightCache> lightGpu;
  LightCacheCpu lightCpu;
  std::unique_ptr<probe::ProbeField> gpuField;
  std::unique_ptr<probe::ProbeFieldCpu> cpuField;
  std::vector<gpu_shared::GpuLight> lights;
  gpu_shared::GpuSky sky{};
  std::unique_ptr<CascadeStackImage> previous;
  // Runs after the light cache and before the probes of each GPU frame (e.g. ObjectScene::update).
  std::function<void(const CascadeStackImage&)> beforeProbes;

  GiHarness(gpu::Context& ctx, const probe::ProbeFieldSettings& s, std::uint32_t cascades,
            bool cpu = true, bool gpu = true)
      : runCpu(cpu), runGpu(gpu), settings(s) {
    if (runGpu) {
      scene = std::make_unique<GpuStackScene>(ctx);
      lightGpu = std::make_unique<LightCache>(ctx);
      gpuField = std::make_unique<probe::ProbeField>(ctx, s, cascades);
    }
    if (runCpu) cpuField = std::make_unique<probe::ProbeFieldCpu>(s, cascades);
  }

  // One frame: uploads the image (whole, when `upload`), relights dirty pages, updates probes.
  void step(const CascadeStackImage& image, probe::ProbeFrameInputs in, std::uint64_t frame,
            bool upload = true) {
    in.sky = sky;
    // A drift is a light change for the light cache (it relights), not for the probes.
    const std::vector<std::uint32_t> dirty =
        lightDirtyPages(previous.get(), image, in.lightsChanged || in.lightsDrifting);
    if (runGpu) {
      if (upload) scene->uploadAll(image);
      lightGpu->update(*scene, lights, sky, dirty, image.voxelSize0);
      if (beforeProbes) beforeProbes(image);
      gpuField->update(*scene, image, lightGpu->radianceBuffer(), in, frame);
    }
    if (runCpu) {
      lightCpu.update(image, lights, sky, dirty, image.voxelSize0);
      cpuField->update(image, lightCpu.radiance(), in, frame);
    }
    previous = std::make_unique<CascadeStackImage>(image);
  }

  std::vector<glm::vec3> sampleGpu(std::span<const gpu_shared::ProbeQuery> q) {
    return gpuField->sample(*scene, lightGpu->radianceBuffer(), q);
  }
};

// The probe field tests' bunny scene: a sun and a blue sky (set on `h`), and the inputs of a
// frame seen from the streamed bunny's camera (its position) towards the bunny.
inline probe::ProbeFrameInputs lightBunnyScene(GiHarness& h, const CascadeStackImage& img,
                                               glm::dvec3 camera) {
  h.sky.zenith = glm::vec4(0.5f, 0.6f, 0.9f, 0.0f);
  h.sky.horizon = glm::vec4(0.8f, 0.8f, 0.8f, 0.0f);
  h.lights = sunLights(img, glm::vec3(-0.3f, -1.0f, -0.4f), 3.0f);
  probe::ProbeFrameInputs in;
  in.cameraWorld = camera;
  in.viewDirection = glm::vec3(glm::normalize(glm::dvec3(0.0, 0.1, 0.0) - camera));
  return in;
}

}  // namespace sdfstream::test
