// Frames in flight against blocking frames: the same streamed fly-through (world, path, lights,
// moving objects) run twice in one process, once with GiSystem::update (record, submit, wait:
// the CPU idles while the GPU works) and once the way an engine hosts it, GiSystem::record into
// its own command buffers with framesInFlight frames in flight and one submission per frame.
// Reports frames per second and the main thread's CPU time per frame for both, and their ratios.
#pragma once

#include <cstdint>
#include <filesystem>

namespace sdfstream::bench {

struct FrameLoopOptions {
  std::filesystem::path world;  // a world pack
  std::filesystem::path out;    // summary.md and frames.csv are written here
  int frames = 300;             // measured frames per mode
  int warmup = 30;              // frames run first in each mode, not measured
  std::uint32_t objects = 100;  // scripted moving objects along the path
  int cascades = 4;
  double speed = 20.0;          // metres per second of camera travel (60 frames per second)
  std::uint32_t framesInFlight = 2;
  bool validation = false;
};

// Throws InputError for a bad world, std::runtime_error for Vulkan failures.
void runFrameLoopBench(const FrameLoopOptions& options);

}  // namespace sdfstream::bench
