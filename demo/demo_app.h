// The demo of `sdfstream demo`: imports the built-in scene (or a given layout), converges the GI
// probes and renders three views lit by a sun and a gradient sky, a fourth with scripted moving
// objects (GPU only), and the Cornell box when its GLB is there. Per view NAME it writes
// view-NAME.png (direct + indirect light), view-NAME-direct.png and view-NAME-indirect.png; then
// world/ (the imported scene) and report.md (demo/demo_report.h).
#pragma once

#include <filesystem>
#include <optional>

#include "demo/render_options.h"
#include "gpu/context.h"

namespace sdfstream {

struct DemoOptions {
  std::filesystem::path out = "out/demo";
  std::filesystem::path scene;  // a layout; empty: the built-in one (demo/default_scene.h)
  int width = 640, height = 480;
  RenderOptions render;
  bool objects = true;                           // the objects view (needs a device)
  std::optional<std::filesystem::path> cornell;  // the Cornell box GLB; none: skipped
  float cornellExposureStops = 1.5f;             // the box's exposure (it is lit by one spot)
  std::optional<gpu::ContextOptions> device;     // none: the CPU reference (direct light only)
};

// Runs the demo and writes its outputs; returns 0. Throws InputError for a scene that cannot be
// imported or found.
int runDemo(const DemoOptions& options);

}  // namespace sdfstream
