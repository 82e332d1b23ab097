// The probe update of one probe volume (issue 5 item 2: trace -> shade -> blend -> borders) on
// the CPU: the reference of the GPU passes in gi/probe_volume.h, running the very same math
// (gi/probe_update_cpu.cpp includes shaders/probe_update.glsl as C++). Also the settings and the
// GPU-visible parameters both share.
//
// Units: positions and distances are cascade-0 voxels relative to cascade 0's minimum corner
// (CascadeStackImage::toStack). Irradiance is linear RGB (W/m² per unit of the scene's radiance).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/probe_layout.h"
#include "streaming/cascade_stack.h"

namespace sdfstream::probe {

struct ProbeVolumeSettings {
  glm::uvec3 grid{gpu_shared::kProbeGridDefault};         // probes per axis (>= 1 each)
  float spacing = float(gpu_shared::kProbeSpacingCells);  // cascade-0 voxels between probes
  glm::vec3 origin{0.0f};  // probe (0,0,0): cascade 0's minimum corner, so probes = grid points
  std::uint32_t raysPerProbe = gpu_shared::kProbeDefaultRays;
  float irradianceHysteresis = gpu_shared::kProbeDefaultHysteresis;
  float depthHysteresis = gpu_shared::kProbeDefaultHysteresis;
  bool adaptiveHysteresis = false;  // per-texel change heuristic (M21 Sec. 4.3), irradiance only
  float maxDepth = 2.0f * 8.0f * 1.7320508f;  // depth a miss records (two probe diagonals), voxels
  float irradianceGamma = gpu_shared::kProbeIrradianceGamma;
  float depthSharpness = gpu_shared::kProbeDepthSharpness;
  float selfShadowBias = gpu_shared::kProbeDefaultSelfShadowBias;
  float backfaceDepthScale = gpu_shared::kProbeBackfaceDepthScale;
  float minVariance = gpu_shared::kProbeMinVariance;
  glm::vec3 skyRadiance{0.0f};     // radiance a miss returns (constant sky), linear RGB
  float bounceGain = 1.0f;         // scales the previous frame's irradiance at hits (multi-bounce)
  std::uint32_t maxSteps = 256;    // sphere-tracing iterations per ray (all cascades together)
  float hitEpsilon = 0.02f;        // voxels
  float traceDistance = 1e30f;     // tMax of probe rays, cascade-0 voxels (default: whole stack)
  std::uint64_t rotationSeed = 1;  // frame f's ray rotation = randomRotation(seed mix f)

  std::uint32_t probeCount() const { return grid.x * grid.y * grid.z; }
};

// Storage sizes (elements) of one volume: irradiance atlas (vec4 per tile texel), depth atlas
// (vec2 per tile texel), ray results (vec4 per ray). Layout: shaders/probe_update.glsl.
std::size_t irradianceTexelCount(const ProbeVolumeSettings& s);
std::size_t depthTexelCount(const ProbeVolumeSettings& s);
std::size_t rayCount(const ProbeVolumeSettings& s);

// The GPU struct of update number `frame` (its ray rotation is drawn from the seed and frame).
gpu_shared::ProbeVolume volumeParams(const ProbeVolumeSettings& s, std::uint64_t frame);
// Push constants of the update passes; counts.y and mode.x are set per dispatch by the caller.
gpu_shared::ProbeUpdatePushConstants updatePushConstants(const ProbeVolumeSettings& s,
                                                         std::uint32_t cascadeCount,
                                                         bool firstUpdate);

// Decoded irradiance of a probe's interior texel (0..5 per axis) / mean over its 36 interior
// texels, read from an irradiance atlas (CPU or downloaded from the GPU).
glm::vec3 irradianceTexel(std::span<const glm::vec4> atlas, std::uint32_t probe, glm::uvec2 texel,
                          float gamma);
glm::vec3 meanIrradiance(std::span<const glm::vec4> atlas, std::uint32_t probe, float gamma);

// irradiance(x, n, view) of a volume's stored probes (probe_sample.comp's reference):
// 8-probe trilinear x backface x Chebyshev weights (probeSampleVolume, probe_update.glsl).
// Atlas sizes must match the settings (asserted). Thread-safe; parallel over queries (TBB).
std::vector<glm::vec3> sampleIrradianceCpu(const ProbeVolumeSettings& settings,
                                           std::span<const glm::vec4> irradiance,
                                           std::span<const glm::vec2> depth,
                                           std::span<const gpu_shared::ProbeQuery> queries);

// CPU reference of one volume. Memory: probes × (64·16 + 256·8 + rays·16) bytes.
// Not thread-safe; update() itself runs in parallel (TBB).
class ProbeUpdateCpu {
 public:
  explicit ProbeUpdateCpu(const ProbeVolumeSettings& settings);

  // One update against the stack: trace + shade every ray (reading the current irradiance for
  // the bounce), blend every interior texel, copy borders. The first update after construction
  // or reset() uses hysteresis 0.
  void update(const CascadeStackImage& stack, std::uint64_t frame);
  void reset();  // all texels back to zero (never written)

  const ProbeVolumeSettings& settings() const { return settings_; }
  std::span<const glm::vec4> irradiance() const { return irradiance_; }
  std::span<const glm::vec2> depth() const { return depth_; }
  std::span<const glm::vec4> rays() const { return rays_; }  // last update's (radiance, depth)

 private:
  ProbeVolumeSettings settings_;
  std::vector<glm::vec4> irradiance_;
  std::vector<glm::vec2> depth_;
  std::vector<glm::vec4> rays_;
  bool firstUpdate_ = true;
};

}  // namespace sdfstream::probe
