#include "demo/demo_report.h"

#include <algorithm>

#include "core/stats.h"

namespace sdfstream {
namespace {

// The settings table at the top of the report.
void writeSettings(std::ostringstream& report, const DemoReport& r) {
  const RenderOptions& options = r.options;
  const SceneLight* sun = options.lights.lights.empty() ? nullptr : &options.lights.lights[0];
  report << "# sdfstream demo report\n\n"
         << "| item | value |\n|---|---|\n"
         << "| scene | " << r.scene << " |\n"
         << "| device | " << r.device << " |\n"
         << "| triangles | " << r.triangles << " |\n"
         << "| voxel size | " << r.voxelSize << " m |\n"
         << "| bricks in world | " << r.bricks << " (all resident in one cascade) |\n"
         << "| import time (load + mesh to SDF bricks) | " << r.importSeconds << " s |\n"
         << "| import time per million triangles | "
         << r.importSeconds / (double(r.triangles) / 1e6) << " s |\n"
         << "| image size | " << r.width << " x " << r.height << " |\n"
         << "| GI | " << (options.gi ? "on" : "off") << ", " << options.giFrames
         << " GI frames (camera fixed) before the first view; "
         << options.renderer.settings.probes.raysPerProbe << " rays per probe; 17^3 probes |\n"
         << "| sun | ";
  if (sun)
    report << "travels (" << sun->direction.x << ", " << sun->direction.y << ", "
           << sun->direction.z << "), irradiance " << sun->intensity;
  else
    report << "none";
  report << " |\n| sky | zenith (" << options.lights.sky.zenith.x << ", "
         << options.lights.sky.zenith.y << ", " << options.lights.sky.zenith.z << "), horizon ("
         << options.lights.sky.horizon.x << ", " << options.lights.sky.horizon.y << ", "
         << options.lights.sky.horizon.z << ") |\n"
         << "| shading | emission + albedo/pi (E_direct + E_indirect); direct light "
         << (options.renderer.shading.direct == gpu_shared::kShadeDirectPixel
                 ? "per pixel (SDF soft shadows)"
                 : "from the light cache")
         << "; exposure " << options.exposureStops << " EV, ACES fitted, sRGB |\n"
         << "| Cornell box | " << r.cornell << " |\n"
         << "| wall time of the three scene views (GI frames included) | " << r.sceneRenderSeconds
         << " s |\n\n"
         << "Each view NAME has view-NAME.png (final), view-NAME-direct.png and "
            "view-NAME-indirect.png (the two parts of the final image, tone-mapped alike).\n\n";
}

void writeGiFrames(std::ostringstream& report, const DemoTables& tables) {
  report << "## GI frames\n\nProbe update GPU time per frame (classify, select, trace + shade, "
            "blend, borders; the hit cache makes later frames cheaper), the light cache (run "
            "when the lights or pages change: the first frame), and the frames after which "
            "the mean indirect irradiance over a fixed subset of the view's hit pixels stays "
            "within 2% of its final value.\n\n"
            "| view | GI frames | probe ms mean | probe ms max | probe ms last | light cache ms "
            "| frames to converge | last frame's passes (ms) |\n"
            "|---|---|---|---|---|---|---|---|\n"
         << tables.gi.str()
         << "\nMean indirect irradiance (luminance) over the subset after each GI frame:\n\n"
            "| view | frame 1, 2, ... |\n|---|---|\n"
         << tables.convergence.str() << "\n";
}

void writeCardBounce(std::ostringstream& report, glm::vec3 on, glm::vec3 off) {
  report << "### Objects bounce the light they receive (cards)\n\nView `objects-no-cards` repeats "
            "view `objects` with the objects' cards off: a probe ray that hits an object then "
            "sees only its albedo times the probes' light, no sunlight. "
            "view-objects-card-bounce.png is what the cards add to view-objects-indirect.png "
            "(x16): the red crate's sunlit faces bounce red onto the ground around it.\n\n"
         << "| mean indirect irradiance (subset of the view) | R | G | B |\n|---|---|---|---|\n"
         << "| cards on | " << on.r << " | " << on.g << " | " << on.b << " |\n"
         << "| cards off | " << off.r << " | " << off.g << " | " << off.b << " |\n\n";
}

void writeObjects(std::ostringstream& report, const ObjectViewStats& stats, int giFrames) {
  report << "## Moving objects\n\nView `objects` is view `front` after " << giFrames
         << " more GI frames (" << giFrames / 30.0
         << " s of scripted motion at 30 frames per second) with " << stats.instances
         << " moving objects (a sphere circling 0.4 m above the ground, a cube dropping onto it, "
            "a red crate driving a loop): they cast hard shadows in view-objects-direct.png, and "
            "the probes trace them, so view-objects-indirect.png is darker than "
            "view-front-indirect.png under and beside them (their indirect shadows).\n\n"
         << "| item | value |\n|---|---|\n"
         << "| pixels on objects | " << stats.pixels << " |\n"
         << "| object region passes, all " << giFrames << " GI frames | "
         << stats.regionMilliseconds << " ms |\n"
         << "| last GI frame: probe rays that searched the objects / hit one | " << stats.probeRays
         << " / " << stats.probeRayHits << " |\n\n";
}

}  // namespace

void DemoTables::addView(const std::string& name, const ViewResult& r, bool withGi) {
  passes << "| " << name << " | shade_primary (trace + direct light) | " << r.shadeMilliseconds
         << " | " << (r.rays / (r.shadeMilliseconds * 1e3)) << " |\n";
  if (!withGi) return;
  passes << "| " << name << " | probe_sample (" << r.hits << " hit pixels) | "
         << r.sampleMilliseconds << " | |\n";
  if (r.probeMilliseconds.empty()) {
    gi << "| " << name << " | 0 (probes of the previous view reused) | | | | | | |\n";
    return;
  }
  gi << "| " << name << " | " << r.probeMilliseconds.size() << " | " << mean(r.probeMilliseconds)
     << " | " << *std::max_element(r.probeMilliseconds.begin(), r.probeMilliseconds.end()) << " | "
     << r.probeMilliseconds.back() << " | " << r.lightMilliseconds << " | " << r.framesToConverge
     << " |";
  for (const auto& p : r.probePasses) gi << " " << p.name << " " << p.milliseconds << ";";
  gi << " |\n";
  convergence << "| " << name << " |";
  for (const glm::vec3& e : r.convergence) convergence << " " << luminance(e);
  convergence << " |\n";
}

std::string demoReport(const DemoReport& r, const DemoTables& tables) {
  std::ostringstream report;
  writeSettings(report, r);
  report << "## Per-pass GPU times\n\n| view | pass | ms | MRays/s |\n|---|---|---|---|\n"
         << tables.passes.str() << "\n";
  if (r.options.gi) writeGiFrames(report, tables);
  if (r.objects) writeObjects(report, *r.objects, r.objectGiFrames);
  if (r.indirectCardsOn && r.indirectCardsOff)
    writeCardBounce(report, *r.indirectCardsOn, *r.indirectCardsOff);
  report << "Absolute times mean something only on a real GPU; on lavapipe they measure the CPU.\n";
  return report.str();
}

}  // namespace sdfstream
