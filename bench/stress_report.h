// What `sdfstream stress` measured, and how it is written: results.csv (one row per
// object count x mode), frames.csv (every measured frame), summary.md (the table, the goal check,
// the 0-object check, scaling) and three PNG plots of GPU time vs object count (demo/plot.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "gi/gi_host_times.h"

namespace sdfstream::bench::stress {

// How probe rays meet the moving objects in a run.
enum class Mode {
  Static,          // setObjects(nullptr): the static-only probe update, the baseline
  StaticRepeat,    // the same again: the noise floor of the comparisons with the baseline
  Regions,         // objects traced through the macro-region lists (the design)
  Naive,           // every probe ray tests every instance (ObjectScene::setNaiveTraversal)
  RegionsNoCards,  // regions with the cards off: object hits without their own direct light
};
// "static", "static-repeat", "regions", "naive", "regions-no-cards"
const char* modeName(Mode mode);
inline bool hasObjects(Mode mode) {
  return mode == Mode::Regions || mode == Mode::Naive || mode == Mode::RegionsNoCards;
}

// One measured frame. GPU times are timestamp queries around each pass (milliseconds).
struct StressFrame {
  int frame = 0;  // within its run, warm-up frames included (motion time t = frame / 60 s)
  // object_regions_*: count (+ subcount), scan (+ rank, subscan), fill.
  double regionCountMs = 0.0, regionScanMs = 0.0, regionFillMs = 0.0;
  double probeMs = 0.0;  // every probe pass of the update
  double traceMs = 0.0;  // its probe_trace pass
  double lightMs = 0.0;  // light cache (relights dirty pages, object-shadowed pages included)
  // Cards: the card light pass (light_cache_cards, part of lightMs), instances it relit, the
  // frames since the longest-unlit instance was lit, and the card atlas + light in MiB.
  double cardLightMs = 0.0;
  std::uint32_t cardRelit = 0;
  std::uint64_t cardStaleFrames = 0;
  double cardMiB = 0.0;
  std::uint32_t pagesRelit = 0, objectPagesRelit = 0;
  std::uint32_t probesUpdated = 0, raysTraced = 0, raysCached = 0;
  std::uint32_t objectRays = 0, objectHits = 0, objectSteps = 0;
  // Host CPU time: the scripted motion, then GiSystem's recording of the frame by part
  // (GiHostTimes: scene upload, objects, shadow pages, light cache, probe passes; total).
  double motionMs = 0.0;
  GiHostTimes host;
  double wallMs = 0.0;  // motion + GiSystem::update, its submit and wait for the GPU included

  double hostMs() const { return motionMs + host.totalMs; }  // what the host spends, no waits

  double regionMs() const { return regionCountMs + regionScanMs + regionFillMs; }
  // What the objects and the probe update cost together: what the goal compares with static.
  double costMs() const { return regionMs() + probeMs; }
};

struct StressRun {
  std::uint32_t objects = 0;
  Mode mode = Mode::Static;
  std::string skipped;                // why the run was not made ("" = it was)
  std::vector<StressFrame> frames;    // measured frames only
  std::uint64_t nonFiniteTexels = 0;  // summed over the irradiance checks
  int irradianceChecks = 0;           // downloads of every probe's irradiance
  // Card light texels whose radiance came out NaN or infinite over the run (counted by the card
  // light pass itself; also in nonFiniteTexels).
  std::uint64_t nonFiniteCardTexels = 0;
  // Cards captured by the run's first frame: meshes, and the capture's GPU milliseconds.
  std::uint32_t meshesCaptured = 0;
  double captureMs = 0.0;
  std::uint64_t validationMessages = 0;
  double wallSeconds = 0.0;  // warm-up and checks included
};

// Medians over a run's measured frames (totals where said).
struct RunSummary {
  double regionCountMs = 0, regionScanMs = 0, regionFillMs = 0, regionMs = 0;
  double regionUsPerInstance = 0;  // regionMs / objects, microseconds (0 without objects)
  double probeMs = 0, probeP99Ms = 0, traceMs = 0, lightMs = 0, costMs = 0, hostMs = 0;
  double motionMs = 0, wallMs = 0;
  GiHostTimes host;  // each part's median
  double pagesRelit = 0, objectPagesRelit = 0, probesUpdated = 0, raysTraced = 0;
  double objectRays = 0, objectHits = 0, objectSteps = 0;
  std::uint64_t raysTracedTotal = 0, objectRaysTotal = 0, objectStepsTotal = 0;
  double stepsPerObjectRay = 0;  // objectStepsTotal / objectRaysTotal
  double cardLightMs = 0, cardRelit = 0, cardStaleFrames = 0, cardMiB = 0;
};
RunSummary summarize(const StressRun& run);

// What the run was made on and with, for the summary's header.
struct StressSetup {
  std::string world, device, command;
  bool software = false;  // a CPU Vulkan device: times are not a GPU's
  bool validation = false;
  int cascades = 0, regionCascades = 0, frames = 0, warmup = 0;
  std::uint32_t probeBudget = 0, raysPerProbe = 0;
  double voxel0 = 0.0;
  std::string camera, area;  // described in words
  std::uint64_t seed = 0;
  int runsPlanned = 0;  // runs (skipped ones included) the command will make in all
};

// The outcome of the run's checks (also decides the exit code).
struct StressChecks {
  std::uint64_t nonFiniteTexels = 0, nonFiniteCardTexels = 0, validationMessages = 0;
  // The 0-object run did no object work at all: no region pass, no probe ray searched objects,
  // in any frame (with no object nothing is dispatched; anything else fails the run).
  bool zeroObjectsNoObjectWork = true;
  // ... and traced exactly the static-only run's rays in every frame. Reported, not required:
  // the probe selection at the ray budget's cutoff depends on thread order (probe_field.glsl,
  // probeSelectPass), so two static-only runs can differ too; the static-repeat run shows by how
  // much.
  bool zeroObjectsSameRays = false;
  std::string goalLine, zeroLine;  // plain sentences for the summary and stdout
  bool passed() const {
    return nonFiniteTexels == 0 && validationMessages == 0 && zeroObjectsNoObjectWork;
  }
};
StressChecks checkRuns(const std::vector<StressRun>& runs);

// The per-(count, mode) table as markdown (printed to stdout too).
std::string stressTable(const std::vector<StressRun>& runs);

// Writes results.csv, frames.csv, summary.md, probe-update.png, probe-trace.png and
// region-build.png into dir (which must exist; the caller makes the directory atomic).
void writeStressReport(const std::filesystem::path& dir, const StressSetup& setup,
                       const std::vector<StressRun>& runs, const StressChecks& checks);

}  // namespace sdfstream::bench::stress
