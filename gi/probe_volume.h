// One probe volume on the GPU (issue 5 item 2), cascade 0 for now: the probe update as three
// compute passes over storage buffers -- probe_trace (one invocation per ray: sdfTraceStack +
// shading with the previous frame's irradiance) -> probe_blend interior (one invocation per
// interior texel: cosine / power-cosine weights, hysteresis, gamma-5 encoding) -> probe_blend
// border (probeBorderSource copies). The math is shaders/probe_update.glsl; gi/probe_update_cpu.h
// is the CPU reference of the same passes and holds the settings.
//
// Not yet: scrolling (toroidal probe indexing), relocation, states, hit/light caches, more
// cascades; the scene upload is a full copy (no dirty-slot sync).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "gi/probe_update_cpu.h"
#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"
#include "streaming/cascade_stack.h"

namespace sdfstream::probe {

class ProbeVolume {
 public:
  // Allocates the volume's buffers (see ProbeUpdateCpu for the sizes), all texels zero.
  // Throws std::runtime_error when allocation fails.
  ProbeVolume(gpu::Context& context, const ProbeVolumeSettings& settings);

  // Uploads the whole stack image (page tables, params, every atlas slot); blocking. Call again
  // whenever the stack changed. Atlas sizes must not change between calls (asserted).
  void uploadScene(const CascadeStackImage& stack);

  // One update (trace -> blend -> borders) of frame `frame` against the last uploaded scene;
  // blocks until the GPU is done. The first update after construction/reset uses hysteresis 0.
  void update(std::uint64_t frame);
  void reset();

  const ProbeVolumeSettings& settings() const { return settings_; }
  // Blocking downloads of the current storage (layouts: shaders/probe_update.glsl).
  std::vector<glm::vec4> downloadIrradiance() const;
  std::vector<glm::vec2> downloadDepth() const;
  std::vector<glm::vec4> downloadRays() const;
  // irradiance(x, n, view) at each query from the current probes (probe_sample.comp); blocking.
  std::vector<glm::vec3> sample(std::span<const gpu_shared::ProbeQuery> queries);

  // GPU time of the last update's passes ("probe_trace", "probe_blend", "probe_border") or of
  // the last sample() ("probe_sample").
  const std::vector<gpu::PassTiming>& lastTimings() const { return timings_; }

  // Device buffers, for passes that read the probes (sampling).
  const gpu::Buffer& volumeBuffer() const { return volume_; }
  const gpu::Buffer& irradianceBuffer() const { return irradiance_; }
  const gpu::Buffer& depthBuffer() const { return depth_; }

 private:
  gpu::Context& context_;
  ProbeVolumeSettings settings_;
  gpu::ComputePipeline trace_, blend_, sample_;
  gpu::Buffer volume_;  // one gpu_shared::ProbeVolume, host-written per update
  gpu::Buffer irradiance_, depth_, rays_;
  gpu::Buffer pageTables_, distance_, albedo_, emission_, params_;
  gpu::Buffer queries_, results_;  // grown on demand by sample()
  std::uint32_t cascadeCount_ = 0;
  bool firstUpdate_ = true;
  std::vector<gpu::PassTiming> timings_;
};

}  // namespace sdfstream::probe
