// CPU reference of the probe field (gi/probe_field.h): the same passes in the same order --
// classify, select (count, emit), trace + shade, blend, borders -- running the very same math
// (gi/probe_field_cpu.cpp includes shaders/probe_field_storage.glsl, so shaders/probe_field.glsl
// and its pass files, as C++), and the storage layouts the GPU uses, so tests compare them texel
// by texel. Also the storage sizes both share.
//
// Not thread-safe; update() itself runs in parallel (TBB). Memory: see probeFieldBytes().
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gi/probe_field_frame.h"

namespace sdfstream::probe {

// Element counts of the field's storage for `cascades` volumes.
struct ProbeFieldSizes {
  std::size_t probes = 0;            // volumes x probes per volume
  std::size_t irradianceTexels = 0;  // vec4 each
  std::size_t depthTexels = 0;       // vec2 each
  std::size_t rays = 0;              // 2 vec4 each: result, direction (list capacity x rays)
  std::size_t cacheEntries = 0;      // uvec2 each (probes x rotations x rays; 1 when off)
  // uvec4 each: the bounce passes' work (probe_bounce.comp): cells to look up, then rays that
  // wait for one, each at most one per ray (2 x list capacity x rays; 1 when the cells are off).
  // The bounce cells themselves (uvec2 per atlas material voxel) grow with the atlas.
  std::size_t bounceWork = 0;
  std::size_t bytes() const;
};
ProbeFieldSizes probeFieldSizes(const ProbeFieldSettings& s, std::uint32_t cascades);

// The frame's statistics (kProbeStat* of probe_layout.h).
struct ProbeFieldStats {
  std::uint32_t classCounts[gpu_shared::kProbeClassCount] = {};
  std::uint32_t probesUpdated = 0;
  std::uint32_t raysTraced = 0;
  std::uint32_t raysCached = 0;
  std::uint64_t steps = 0;
  std::uint32_t states[4] = {};  // off, sleeping, awake, vigilant
  std::uint32_t cacheInvalidated = 0;
  std::uint32_t objectRays = 0;   // rays that searched the moving objects (GPU only)
  std::uint32_t objectHits = 0;   // ... and hit one before the static scene
  std::uint32_t objectSteps = 0;  // object sphere-tracing steps
  std::uint32_t bounceCells = 0;  // bounce cells looked up afresh (probe_trace.glsl)
  std::uint32_t bounceRays = 0;   // rays that waited for a bounce cell or looked up their own
  std::uint32_t bounceOwn = 0;    // ... of them, those that looked up their own
};
ProbeFieldStats decodeStats(std::span<const std::uint32_t> raw);

class ProbeFieldCpu {
 public:
  ProbeFieldCpu(const ProbeFieldSettings& settings, std::uint32_t cascades);

  // One frame against `stack`, with `lightRadiance` the light cache (one RGB9E5 per atlas
  // material voxel, gi/light_cache.h).
  void update(const CascadeStackImage& stack, std::span<const std::uint32_t> lightRadiance,
              const ProbeFrameInputs& inputs, std::uint64_t frame);
  void reset();

  // irradiance(x, n, view) of the current probes, parallel over queries (0 for a query whose
  // normal is zero, as on the GPU). GroupsShareTraces is
  // probe_sample.comp's rule (kProbeSampleShareLanes consecutive queries in the same cage split
  // its SDF tests, probeGroupSharesCage); PerQuery traces every query's own tests
  // (probeFieldIrradiance, what an engine's shader computes per pixel). `counts` (GroupsShareTraces
  // only), when given, receives how many cages were sampled, how many of them a group shared, how
  // many SDF tests were traced, and how many tracing every query's own would have taken.
  // AsSettings: as ProbeFieldSettings::shareSdfTests says.
  enum class SampleTraces { AsSettings, GroupsShareTraces, PerQuery };
  struct SampleCounts {
    std::uint64_t cages = 0, sharedCages = 0, traces = 0, ownTests = 0;
  };
  std::vector<glm::vec3> sample(const CascadeStackImage& stack,
                                std::span<const gpu_shared::ProbeQuery> queries,
                                SampleTraces traces = SampleTraces::AsSettings,
                                SampleCounts* counts = nullptr) const;
  // The near-field variant's reference (ProbeFieldSettings::nearFieldRays > 0; sample() then
  // throws std::logic_error): each query's own short rays (shaders/probe_near_field.glsl), their
  // hits lit by `lightRadiance` (the light cache, one RGB9E5 per atlas material voxel).
  std::vector<glm::vec3> sampleNearField(const CascadeStackImage& stack,
                                         std::span<const std::uint32_t> lightRadiance,
                                         std::span<const gpu_shared::ProbeQuery> queries) const;
  // ProbeField::sampleHalfResolution's reference: an image of queries (width × height, row by
  // row; zero normal: no surface) sampled at one pixel per blockSize × blockSize block in the
  // GPU pass's order (gi/probe_upsample.h), the rest upsampled.
  std::vector<glm::vec3> sampleHalfResolution(const CascadeStackImage& stack,
                                              std::span<const gpu_shared::ProbeQuery> image,
                                              std::uint32_t width, std::uint32_t height,
                                              std::uint32_t blockSize = 2) const;

  // Ray `ray` of hit-cache rotation slot `slot` of global probe g, traced afresh against `stack`
  // from the probe's current position with the last frame's constants (tests compare it with
  // the cached entry). Returns (hit ? t in cascade-0 voxels : -1, hit cascade).
  glm::vec2 traceFresh(const CascadeStackImage& stack, std::uint32_t g, std::uint32_t slot,
                       std::uint32_t ray) const;
  // The probe's current position (grid point + relocation), cascade-0 voxels.
  glm::vec3 probePosition(std::uint32_t g) const;

  const ProbeFieldSettings& settings() const { return settings_; }
  const ProbeFieldStats& lastStats() const { return stats_; }
  std::span<const glm::vec4> irradiance() const { return irradiance_; }
  std::span<const glm::vec2> depth() const { return depth_; }
  std::span<const glm::vec4> probeData() const { return data_; }
  // Per probe its history word (shaders/probe_field.glsl, probeHistoryPack).
  std::span<const glm::uvec4> history() const { return history_; }
  std::span<const glm::uvec2> hitCache() const { return cache_; }
  // The bounce cells (probe_trace.glsl), uvec2 per atlas material voxel as two words each.
  std::span<const std::uint32_t> bounceCells() const { return bounceCells_; }
  const ProbeFieldFrame& lastFrame() const { return frame_; }
  // The global probes the last update traced and blended, in list order.
  std::span<const std::uint32_t> lastUpdateList() const {
    return std::span<const std::uint32_t>(list_).first(
        std::min<std::size_t>(stats_.probesUpdated, list_.size()));
  }

 private:
  ProbeFieldSettings settings_;
  std::uint32_t cascades_;
  ProbeFieldFrameBuilder builder_;
  ProbeFieldFrame frame_;
  std::vector<glm::vec4> data_;
  std::vector<glm::uvec4> history_;
  std::vector<glm::vec4> irradiance_;
  std::vector<glm::vec2> depth_;
  std::vector<glm::vec4> rays_, rayDirs_;
  std::vector<glm::uvec2> cache_;
  std::vector<std::uint32_t> bounceCells_;  // two words per atlas material voxel
  std::vector<glm::uvec4> bounceWork_;
  std::vector<std::uint32_t> list_;
  std::vector<std::uint32_t> rawStats_;
  ProbeFieldStats stats_;
};

}  // namespace sdfstream::probe
