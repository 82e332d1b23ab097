// `sdfstream bench gi`: run time vs error of the probe GI against a
// path-traced reference, over a sweep of the probe settings, with plain DDGI built from the same
// code as the baseline, and the probe-ray traversal against its peers on one frame's rays.
//
// Per scene: source triangles -> world pack (cached under OUT/packs) -> cascade stacks settled
// around the scene's player position (one per cascade count) -> the reference irradiance at the
// visible points of the scene's views (PathTracer, NoDirectLights, cached under OUT/reference) ->
// per configuration a fresh GiSystem: warm-up frames, measured frames (GPU pass times, medians),
// irradiance at every visible point (relMSE, FLIP of albedo/π·E images), the light switched off
// and on again (frames until within 5% of the converged field), device memory. Writes
// results.csv, summary.md and plots (bench/bench_gi_report.h), or with gpuTable only
// gpu-table.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "gpu/context.h"

namespace sdfstream::bench {

struct GiBenchOptions {
  // quick: a reduced sweep on small views that fits in minutes on lavapipe; gpuTable: only the
  // per-pass time table of scripts/bench-gpu (it wins where both are set). Neither: everything.
  bool quick = false, gpuTable = false;
  bool peers = true, verbose = false;
  // diagnose: also where the light goes (bench/bench_gi_diagnose.h) -- diagnoseConfig's probe
  // rays against Embree by cascade, its probes against the reference, and its one-bounce transport
  // against a one-bounce reference, overall and ray by ray.
  bool diagnose = false;
  std::string diagnoseConfig = "default";  // the configuration --diagnose takes apart
  std::vector<std::string> only;           // run just these configurations (empty: all)
  std::filesystem::path out = "out/bench-gi", data = "../shared/data",
                        largeWorld = "out/worlds/village-4km";
  std::vector<std::string> scenes;  // names of benchSceneNames()
  int width = 160, height = 120;    // of every view
  std::uint32_t samples = 512;      // reference paths per point
  int warmup = 32, measured = 6, offFrames = 8, convergeCap = 32;
  // --gpu-table: after the measured frames, run on to this frame and measure again: the settled
  // field's cost beside the young field's (0: skip).
  int settledFrames = 0;
  // --gpu-table: run the configuration list this many times in turn and keep, per configuration,
  // the round with the least probe update + sampling time (the card's clock state can change
  // within a run; the least time is the one least disturbed).
  int rounds = 1;
  double queryOffsetVoxels = 0.5;  // GI queries sit this far off the points along the normal
  gpu::ContextOptions device;
  std::string command;  // the command line, for the reports
};

// The defaults of the mode options.quick / options.gpuTable ask for (frames, view size, samples)
// written into `options`.
void applyGiBenchModeDefaults(GiBenchOptions& options);
// The scenes the mode runs when none are named: quick takes the Breakfast Room when options.data
// has it, else the bunny.
std::vector<std::string> defaultGiBenchScenes(const GiBenchOptions& options);

// Runs every scene and writes the outputs; returns 0. Needs a Vulkan device.
int runGiBench(const GiBenchOptions& options);

}  // namespace sdfstream::bench
