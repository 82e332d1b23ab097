// What `sdfstream demo` writes into report.md: the run's settings, GPU pass times per view, the
// GI frames and their convergence, and the moving objects' view. Rows are collected per view as
// the views are rendered (DemoTables::addView), the report is assembled at the end (demoReport).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>

#include "demo/render_options.h"
#include "demo/view_renderer.h"

namespace sdfstream {

// The markdown table rows of every rendered view, in render order.
struct DemoTables {
  std::ostringstream passes;       // | view | pass | ms | MRays/s |
  std::ostringstream gi;           // | view | GI frames | probe ms ... |
  std::ostringstream convergence;  // | view | mean E_indirect after frame 1, 2, ... |
  // Appends view `name`'s rows (GI rows only with gi).
  void addView(const std::string& name, const ViewResult& r, bool gi);
};

// What the report says about the moving objects of the objects view.
struct ObjectViewStats {
  std::size_t instances = 0, pixels = 0;
  double regionMilliseconds = 0.0;
  std::uint32_t probeRays = 0, probeRayHits = 0;
};

struct DemoReport {
  std::string scene, device;
  std::size_t triangles = 0, bricks = 0;
  double voxelSize = 0.0;
  double importSeconds = 0.0;  // load + mesh to SDF bricks
  int width = 0, height = 0;
  RenderOptions options;
  std::string cornell;                     // one line: what the Cornell box view showed, or why not
  double sceneRenderSeconds = 0.0;         // the three scene views, GI frames included
  std::optional<ObjectViewStats> objects;  // the objects view, when there was one
  // The objects view's mean indirect irradiance (its convergence subset, last GI frame) with the
  // objects' cards on, and again with them off (when both ran).
  std::optional<glm::vec3> indirectCardsOn, indirectCardsOff;
  int objectGiFrames = 0;  // GI frames the objects view ran with them moving
};

// report.md's text.
std::string demoReport(const DemoReport& report, const DemoTables& tables);

}  // namespace sdfstream
