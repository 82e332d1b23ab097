// `sdfstream view`: a window to fly in. A world pack streams around the camera and the GI runs
// on the streamed stack every frame, exactly as in `fly` (demo/streamed_gi.h); the frame is
// shown in a GLFW window through a Vulkan swapchain on a device the viewer owns and sdfstream
// adopts (gpu::Context::adopt), as an engine would host it. The frame never waits on disk.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include "demo/streamed_gi.h"
#include "gi/camera.h"
#include "gpu/context.h"

namespace sdfstream::viewer {

struct ViewOptions {
  StreamedGiOptions world;                 // the pack, streaming budgets, GI settings and lights
  std::filesystem::path out = "out/view";  // screenshots (F12) and script captures
  std::optional<std::filesystem::path> script;  // --script: scripted input (view_script.h)
  std::optional<std::filesystem::path> record;  // --record DIR: every presented frame as PNG
  std::optional<Camera> camera;    // start; none: render's default view (the whole world)
  double speed = 0.0;              // m/s; 0: the world's diagonal in 30 s
  int width = 1280, height = 720;  // window (or, headless, picture) size
  // Render resolution as a fraction of the window's; 0: automatic (1 on a GPU, 1/4 on a CPU
  // Vulkan device, which then stays responsive; the HUD says so).
  double renderScale = 0.0;
  int frames = 0;         // stop after this many frames (0: when closed / at the script's end)
  bool headless = false;  // no window: render the same frames offscreen (captures, --record)
  bool hud = true;
  bool vsync = true;
  std::uint32_t objects = 0;  // scripted moving objects along the default path
  gpu::ContextOptions device;
};

// Runs the viewer until the window closes, Escape, the script ends or `frames` frames; returns
// the exit code (1 when validation reported messages). Throws std::runtime_error / InputError
// with one line (no display, bad pack, bad script).
int runView(const ViewOptions& options);

}  // namespace sdfstream::viewer
