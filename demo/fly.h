// The fly-through of `sdfstream fly`: drives a camera along a path over a world pack, streaming
// its tiles into the cascade stack without ever waiting on disk, updates the GI core on the
// streamed stack every frame, renders frames shaded with direct + indirect light, and writes
// streaming and GI metrics. Scripted moving objects spread along the path move every frame; the
// GI traces them, so they cast direct and indirect shadows on the streamed world.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include <glm/glm.hpp>

#include "demo/render_options.h"
#include "gpu/context.h"

namespace sdfstream {

struct FlyOptions {
  std::filesystem::path world;  // a world pack
  std::filesystem::path out;    // frames/, metrics.csv, gi.csv, summary.md, residency/bytes.png
  std::optional<std::filesystem::path> path;  // waypoints (demo/fly_path.h); none: the default
  int frames = 300;                           // at 30 per second of path time
  double speed = 80.0;                        // m/s
  int width = 320, height = 180;
  int imageEvery = 50;  // write every imageEvery-th frame (and the last)
  bool pacing = true;   // 30 frames per wall-clock second, as an interactive application
  bool layers = false;  // also the direct-only and indirect-only PNGs
  int cascades = 6;
  double atlasMiB = 96.0;   // shared brick atlas budget
  double uploadMiB = 16.0;  // brick bytes uploaded per frame at most
  int loaderThreads = 2;
  std::uint32_t objects = 150;  // scripted moving objects along the path (Vulkan only)
  int warmupGiFrames = 0;       // GI frames at the start of the path before the flight
  // Long runs (scripts/soak): fly back and forth along the path instead of stopping at its end;
  // turn every sun about +Y by this many degrees per frame (a moving sun: the light cache
  // relights); keep the per-frame metrics of every metricsEvery-th frame only, so memory stays
  // flat over 100,000 frames.
  bool loop = false;
  double sunDegreesPerFrame = 0.0;
  // A day-to-dusk sweep (demo/time_of_day.h): every sun's elevation, in degrees, at the first and
  // the last frame, moved linearly in between; its colour, its strength and the sky follow.
  std::optional<glm::dvec2> sunSweep;
  int metricsEvery = 1;
  RenderOptions render;         // rayBudget kProbeBudgetOfDevice: chosen by device
  std::optional<gpu::ContextOptions> device;  // none: the CPU reference (direct light only)
};

// Runs the fly-through and writes its outputs. Returns 0, or 1 when tiles failed to load (they
// are listed in summary.md). Throws InputError for a bad pack or path file.
int runFly(const FlyOptions& options);

}  // namespace sdfstream
