// One configuration of `sdfstream bench gi` on one scene, start to finish (bench/bench_gi.h has
// the whole run): a fresh GiSystem on the scene's settled stack, warm-up frames, measured frames,
// the error against the reference, the traversal peers (optional) and the light switch.
#pragma once

#include <functional>
#include <map>
#include <vector>

#include "bench/bench_gi.h"
#include "bench/bench_gi_configs.h"
#include "bench/bench_gi_points.h"
#include "bench/bench_gi_report.h"
#include "bench/bench_gi_scenes.h"
#include "shaders/shared/probe_layout.h"

namespace sdfstream::bench {

// What every configuration of a scene shares.
struct SceneContext {
  gpu::Context& ctx;
  const GiBenchOptions& opt;
  const BenchScene& scene;
  std::map<int, StreamedStack>& stacks;  // by cascade count
  ViewPoints& points;
  std::vector<gpu_shared::ProbeQuery> queries, testQueries;  // one per point; <= 1024 of them
  std::vector<std::size_t> testIndex;                        // testQueries[i] is point testIndex[i]
  // The queries as the sampling pass gets them: each view's in 8×8 pixel tiles, Z-order inside
  // (2×2 quads and 4×2 blocks consecutive), as an engine dispatching over its G-buffer in tiles
  // would give them. sampleQueries[k] is point sampleOrder[k].
  std::vector<gpu_shared::ProbeQuery> sampleQueries;
  std::vector<std::uint32_t> sampleOrder;
  // The same queries as images (views × width × height, row by row; pixels without a point
  // have a zero normal), for sampling at reduced resolution (GiConfig::sampleBlock).
  std::vector<gpu_shared::ProbeQuery> imageQueries;
  // --gpu-table: brings the GPU's clocks up (bench/gpu_clock_warmup.h) before a configuration's
  // timed frames; empty otherwise.
  std::function<void()> warmGpu;
};

// Where runConfig reports what it measures beyond its result row (null: not measured).
struct RunReports {
  SceneReport* peers = nullptr;      // the traversal peers on this configuration's probe rays
  SceneReport* diagnosis = nullptr;  // --diagnose: probe rays, probes, receivers
  // One more frame's probe rays compared ray by ray with the same rays on the triangles under
  // one-bounce transport (meant for a bounceGain-0 run).
  SceneReport* rayRadiance = nullptr;
};

// Runs `cfg`. `keep` receives the final irradiance at every point.
ConfigResult runConfig(SceneContext& sc, const GiConfig& cfg, std::vector<glm::vec3>* keep,
                       const RunReports& into);

}  // namespace sdfstream::bench
