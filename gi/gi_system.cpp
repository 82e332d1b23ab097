#include "gi/gi_system.h"

#include <algorithm>
#include <iterator>

namespace sdfstream {

GiSystem::GiSystem(gpu::Context& context, const GiSettings& settings, std::uint32_t cascades)
    : scene_(context),
      light_(context, settings.light),
      probes_(context, settings.probes, cascades),
      objects_(context, settings.objects) {}

void GiSystem::setObjects(const ObjectLibrary* library, InstanceSet* instances) {
  objectLibrary_ = library;
  instances_ = library ? instances : nullptr;
  probes_.setObjects(instances_ ? &objects_ : nullptr);
}

GiFrameStats GiSystem::update(const CascadeStack& stack, std::span<const std::uint32_t> dirtySlots,
                              const SceneLights& lights, probe::ProbeFrameInputs inputs,
                              std::uint64_t frame) {
  scene_.sync(stack, dirtySlots);
  return run(stack.stackImage(), lights, inputs, frame);
}

GiFrameStats GiSystem::update(const CascadeStackImage& image, const SceneLights& lights,
                              probe::ProbeFrameInputs inputs, std::uint64_t frame) {
  scene_.uploadAll(image);
  return run(image, lights, inputs, frame);
}

GiFrameStats GiSystem::run(const CascadeStackImage& image, const SceneLights& lights,
                           probe::ProbeFrameInputs inputs, std::uint64_t frame) {
  // Lights are world-fixed: the light cache (radiance per voxel) only changes when they do,
  // not when cascade 0 moves and their cascade-relative GPU form with it.
  const bool lightsChanged = lights.version != lightsVersion_ || lights.lights.size() != lightCount_;
  lightsVersion_ = lights.version;
  lightCount_ = lights.lights.size();
  std::vector<std::uint32_t> dirty = lightDirtyPages(previous_.get(), image, lightsChanged);
  const auto gpuLights = toGpu(lights.lights, image);
  const gpu_shared::GpuSky sky = toGpu(lights.sky);
  GiFrameStats stats;
  if (instances_) {
    objects_.update(*objectLibrary_, *instances_, image);
    for (const auto& t : objects_.lastTimings()) stats.objectMilliseconds += t.milliseconds;
    stats.objectInstances = std::uint32_t(instances_->size());
    // Relight only where objects moved: the pages their old and new poses shadow.
    const std::vector<WorldBox> changed = instances_->changedBoxes(*objectLibrary_);
    const std::vector<std::uint32_t> shadowed = objectShadowPages(image, changed, gpuLights);
    stats.objectPagesRelit = std::uint32_t(shadowed.size());
    std::vector<std::uint32_t> merged;
    std::set_union(dirty.begin(), dirty.end(), shadowed.begin(), shadowed.end(),
                   std::back_inserter(merged));
    dirty = std::move(merged);
    instances_->endFrame();
  }
  light_.update(scene_, gpuLights, sky, dirty, image.voxelSize0, instances_ ? &objects_ : nullptr);
  inputs.sky = sky;
  inputs.lightsChanged = inputs.lightsChanged || lightsChanged;
  probes_.update(scene_, image, light_.radianceBuffer(), inputs, frame);

  stats.pagesRelit = light_.pagesRelitLastUpdate();
  for (const auto& t : light_.lastTimings()) stats.lightMilliseconds += t.milliseconds;
  stats.probeMilliseconds = probes_.lastMilliseconds();
  stats.probes = probes_.lastStats();
  previous_ = std::make_unique<CascadeStackImage>(image);
  return stats;
}

std::vector<glm::vec3> GiSystem::irradiance(std::span<const gpu_shared::ProbeQuery> queries) {
  return probes_.sample(scene_, light_.radianceBuffer(), queries);
}

double GiSystem::lastSampleMilliseconds() const { return probes_.lastMilliseconds(); }

}  // namespace sdfstream
