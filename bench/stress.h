// `sdfstream stress`: many moving objects against the static-only GI, headless. Streams
// a world pack around a fixed camera until the cascades settle, then, on that frozen stack, runs
// the GI for a number of frames per configuration -- static-only first (no object scene, and
// once more as the noise floor), then for each object count the same spread, scripted instances
// traced through the macro-region lists and naively (every probe ray against every instance) --
// and reports GPU time per pass against the object count, checks for NaN and validation
// messages, and the goal. The report is bench/stress_report.h.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/gi_system.h"
#include "gpu/context.h"
#include "world/scene_lights.h"

namespace sdfstream::bench {

struct StressOptions {
  std::filesystem::path world;  // a world pack
  std::filesystem::path out = "out/stress";
  std::vector<std::uint32_t> counts = {0, 10, 100, 1000, 10000};  // sorted, no duplicates
  int frames = 1000, warmup = 60;                                 // per run
  std::uint64_t seed = 1;                                         // object placement and motion
  bool naive = true;  // the naive runs, up to naiveMax objects
  std::uint32_t naiveMax = ~0u;
  bool cardsPeer = true;         // per count, the regions run again with the cards off
  std::uint32_t meshes = 2;      // distinct meshes the objects are spread over (spreadObjects)
  double sunOrbitDegrees = 0.0;  // per frame, about the vertical: a moving light (0: still)
  int cascades = 6;
  std::optional<glm::dvec3> camera;          // none: 2 m over the surface below the bounds' centre
  double areaWidth = 0.0, areaHeight = 0.0;  // metres; 0: 256 and 16 cascade-0 voxels
  GiSettings settings;  // probes.rayBudget kProbeBudgetOfDevice: chosen by device
  SceneLights lights;
  gpu::ContextOptions device;
  std::string command;  // the command line, for the summary
};

// Runs the plan and rewrites the outputs (atomically) after every run. Returns 0, or 1 when a
// texel is non-finite, a validation message came, or the 0-object run did any object work.
// Throws InputError for a missing or malformed pack.
int runStress(const StressOptions& options);

}  // namespace sdfstream::bench
