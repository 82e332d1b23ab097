// The GI core in one object (issue 5): the stack's device copy (GpuStackScene), the static
// voxel light cache (LightCache) and the probe field (ProbeField), driven once per frame in the
// order they depend on each other: sync the streamed bricks -> relight the dirty pages -> update
// the probes. Then irradiance(x, n, view) queries for shading. What callers (the demo, the
// benchmarks) use; the tests drive the parts directly to compare them with their references.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "gi/gpu_stack_scene.h"
#include "gi/light_cache.h"
#include "gi/object_scene.h"
#include "gi/probe_field.h"
#include "gi/scene_lights.h"
#include "gpu/context.h"
#include "streaming/cascade_stack.h"

namespace sdfstream {

struct GiSettings {
  probe::ProbeFieldSettings probes;
  LightCacheSettings light;
  ObjectSceneSettings objects;
};

struct GiFrameStats {
  std::uint32_t pagesRelit = 0;
  double lightMilliseconds = 0.0;  // GPU time of the light cache pass (0 when skipped)
  double probeMilliseconds = 0.0;  // GPU time of all probe passes
  double objectMilliseconds = 0.0; // GPU time of the macro-region passes (0 without objects)
  std::uint32_t objectInstances = 0;
  std::uint32_t objectPagesRelit = 0;  // light-cache pages relit because objects moved
  probe::ProbeFieldStats probes;
};

class GiSystem {
 public:
  GiSystem(gpu::Context& context, const GiSettings& settings, std::uint32_t cascades);

  // One frame of a streaming stack: uploads its page tables and the atlas slots it rewrote
  // (CascadeStack::takeDirtySlots), relights dirty pages, updates the probes. Blocking.
  GiFrameStats update(const CascadeStack& stack, std::span<const std::uint32_t> dirtySlots,
                      const SceneLights& lights, probe::ProbeFrameInputs inputs,
                      std::uint64_t frame);
  // The same for a stack image that is uploaded whole (hand-built or static scenes).
  GiFrameStats update(const CascadeStackImage& image, const SceneLights& lights,
                      probe::ProbeFrameInputs inputs, std::uint64_t frame);

  // Moving objects (issue 7), or none (nullptr, the default). Each update then uploads the
  // instances, rebuilds the macro-region lists, relights the pages their moves shadow or
  // unshadow, traces them in the probe update, and consumes the set's change record
  // (instances->endFrame()). Both must outlive their use here.
  void setObjects(const ObjectLibrary* library, InstanceSet* instances);
  const ObjectScene& objects() const { return objects_; }
  ObjectScene& objects() { return objects_; }

  // irradiance(x, n, view) of the current probes (cascade-0 voxels of the last frame's stack).
  std::vector<glm::vec3> irradiance(std::span<const gpu_shared::ProbeQuery> queries);
  double lastSampleMilliseconds() const;

  const GpuStackScene& scene() const { return scene_; }
  const LightCache& lightCache() const { return light_; }
  const probe::ProbeField& probes() const { return probes_; }
  probe::ProbeField& probes() { return probes_; }
  const CascadeStackImage* lastImage() const { return previous_.get(); }

 private:
  GiFrameStats run(const CascadeStackImage& image, const SceneLights& lights,
                   probe::ProbeFrameInputs inputs, std::uint64_t frame);

  GpuStackScene scene_;
  LightCache light_;
  probe::ProbeField probes_;
  ObjectScene objects_;
  const ObjectLibrary* objectLibrary_ = nullptr;
  InstanceSet* instances_ = nullptr;
  std::unique_ptr<CascadeStackImage> previous_;
  std::uint64_t lightsVersion_ = ~std::uint64_t(0);
  std::size_t lightCount_ = 0;
};

}  // namespace sdfstream
