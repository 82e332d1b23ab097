// What `sdfstream bench gi` measured, and how it is written: results.csv (one row per scene x
// configuration), summary.md (tables, Pareto fronts, the default-vs-plain-DDGI verdict per scene,
// the peer table) and one error-vs-time PNG per scene (demo/plot.h).
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "bench/bench_gi_peers.h"
#include "gi/light_cache_work.h"

namespace sdfstream::bench {

// Primary-ray SDF traversal alone (primaryTraceTiming in bench/bench_gi_points.h). The steps
// tell what the time is made of: a SIMD group of 32 lanes runs as long as its longest ray, so
// the steps a lane waits for are the group's most, for the rays in dispatch order (32 pixels of
// a row) and, for comparison, in 8 × 4 pixel tiles.
struct PrimaryTraceTiming {
  std::size_t rays = 0, hits = 0;
  double milliseconds = 0.0;  // median of the timed dispatches; 0: the device has no timestamps
  double minMilliseconds = 0.0, maxMilliseconds = 0.0;  // their spread
  std::uint32_t timedDispatches = 0;  // the median's count: the warm-up's last batch
  double coldMilliseconds = 0.0;      // the warm-up's first dispatch (the clock it found)
  double warmupSeconds = 0.0;
  bool settled = false;       // the warm-up's last two batches agreed (else it ran out of time)
  double meanSteps = 0.0;     // sphere-tracing steps per ray over every cascade
  double p99Steps = 0.0;
  double groupStepsRows = 0.0;   // mean over rays of their 32-ray group's most steps, rows
  double groupStepsTiles = 0.0;  // the same with groups of 8 × 4 pixels
  // The same rays through the CPU reference (gi/cpu_tracer.h): steps per ray by kind, and
  // whether its steps equal the GPU's ray for ray (the same math).
  std::array<double, 5> stepsByKind{};  // TraceStepKinds's order
  bool cpuStepsEqual = false;
};

struct ConfigResult {
  std::string config;  // "default", "plain-ddgi", "rays-32", ...
  std::string family;  // "ours" (default switches) or "plain-ddgi" (baseline switches)
  std::string change;  // what differs from `base`, for the ablation table ("" = a base itself)
  std::string base;    // "default", "spacing-2" (quick mode's switch ablations), "plain-ddgi"
  std::uint32_t rays = 0, spacing = 1, cascades = 0;
  bool hitCache = false, states = false, relocation = false;
  std::string visibility;
  std::size_t probes = 0;
  // GPU milliseconds, medians over the measured frames.
  double updateMs = 0.0;                         // every probe pass of one update
  double sampleMs = 0.0;                         // probe_sample for one view's visible points
  double frameMs = 0.0;                          // updateMs + sampleMs: the x axis of the plots
  double frameBestMs = 0.0, frameWorstMs = 0.0;  // fastest / slowest measured frame
  double sampleNsPerQuery = 0.0;
  double lightRelightMs = 0.0;      // light cache relighting every resident page (light change)
  double lightRelightWarmMs = 0.0;  // --gpu-table: median of forced relights after the measure
  // --gpu-table: a sun moving every frame, one row per relight budget
  // (ConfigRun::measureMovingSun).
  struct MovingSun {
    std::uint32_t budget = 0, residentPages = 0, stalenessFrames = 0;
    double lightMs = 0.0;  // median light-cache ms per frame at steady state
  };
  std::vector<MovingSun> movingSun;
  LightCacheWork lightWork;  // --gpu-table: what the full relight asks of the pass (pages 0: none)
  std::map<std::string, double> passMs;  // per probe pass
  // Work per frame (medians).
  double probesUpdated = 0, raysTraced = 0, raysCached = 0, steps = 0;
  std::array<std::uint32_t, 4>
      probeStates{};  // the last measured frame's off, sleeping, awake, vigilant
  // --gpu-table with settled frames: the same medians once the field has settled (most probes
  // asleep), what a frame costs while nothing changes; afterFrames 0: not measured.
  struct Settled {
    std::uint64_t afterFrames = 0;
    double updateMs = 0.0, sampleMs = 0.0, probesUpdated = 0, raysTraced = 0, raysCached = 0;
    std::map<std::string, double> passMs;
    std::array<std::uint32_t, 4> probeStates{};
  } settled;
  // Error against the path-traced reference at the visible points of every view.
  double relMSE = -1.0;       // < 0: no reference
  double flip = -1.0;         // mean over views
  double energyRatio = 0.0;   // mean luminance of E over mean of E_ref: bias apart from noise
  // Splotches: relative spread of E's and of E_ref's luminance over each view's largest flat
  // region (reference::flatRegionSpread); < 0: no region or no reference.
  double flatSpread = -1.0, flatSpreadReference = -1.0;
  int framesToConverge = -1;  // after the light switches back on; -1 = not within the cap
  // Half-resolution configs: relMSE of the last measured frame's E against full-resolution
  // sampling of the same field (the upsample's own error, apart from the GI's); < 0: not one.
  double halfVsFullRelMSE = -1.0;
  int convergeCap = 0;
  // Device memory, MiB.
  double probeMiB = 0, lightMiB = 0, atlasMiB = 0;
  double memoryMiB() const { return probeMiB + lightMiB + atlasMiB; }
  double wallSeconds = 0.0;  // everything this configuration took on this machine
  bool pareto = false;
};

struct SceneReport {
  std::string name, description;
  std::string skipped;  // non-empty: the scene did not run, and why
  double voxelSize = 0.0;
  int lods = 0;
  double importSeconds = 0.0, referenceSeconds = 0.0;
  std::string referenceCache;  // "computed" / "loaded"
  std::size_t points = 0;
  int views = 0, width = 0, height = 0;
  std::uint32_t referenceSamples = 0;
  double referenceNoise = 0.0;  // expected relMSE of the reference itself (from its 95% CIs)
  double floorRelMSE = 0.0, floorFlip = 0.0;  // between two references of different seeds
  int warmupFrames = 0, measuredFrames = 0;
  std::vector<ConfigResult> configs;
  std::vector<PeerResult> peers;
  std::size_t peerRays = 0;
  std::string peerRaySet;
  std::string diagnosis;  // markdown (--diagnose): bench/bench_gi_diagnose.h
  // --gpu-table: primary-ray SDF traversal alone from the stream camera (primaryTraceTiming).
  PrimaryTraceTiming primary;
  int rounds = 1;  // --gpu-table --rounds: each configuration's fastest of this many rounds
  double seconds = 0.0;
};

struct RunInfo {
  std::string device, mode, command;
  double seconds = 0.0;
};

// Marks each scene's Pareto front (minimise frameMs and relMSE; without a reference, frameMs and
// memory) and writes everything into outDir. Throws InputError(Io) when a file cannot be written.
void writeBenchGiOutputs(const std::filesystem::path& outDir, std::vector<SceneReport>& scenes,
                         const RunInfo& run);

// The real-GPU table (scripts/bench-gpu): absolute per-pass times of a few configurations.
void writeGpuTable(const std::filesystem::path& outDir, const SceneReport& scene,
                   const RunInfo& run);

}  // namespace sdfstream::bench
