#include "demo/demo_app.h"

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_dir.h"
#include "core/stats.h"
#include "core/stopwatch.h"
#include "demo/default_scene.h"
#include "demo/demo_report.h"
#include "demo/moving_objects.h"
#include "demo/pack_lights.h"
#include "demo/view_renderer.h"
#include "world/cornell_light.h"
#include "world/gltf_import.h"
#include "world/mesh_to_sdf.h"
#include "world/scene_layout.h"
#include "world/world_io.h"

namespace fs = std::filesystem;

namespace sdfstream {
namespace {

struct DemoView {
  std::string name;
  Camera camera;
};

// GI frames the objects view runs with its objects moving, after the static views converged the
// probes: enough for the probes around them to follow (vigilant probes blend fast), few enough
// to keep scripts/demo's time (about 1 s each on lavapipe).
constexpr int kObjectGiFrames = 12;

// The scene imported, written to out/world and read back (render what is on disk, checksums
// verified), with what the report says about it. A scene with lights of its own (glTF
// KHR_lights_punctual assets) is lit by them unless --sun was given.
World importScene(const fs::path& scenePath, const fs::path& out, DemoReport& report,
                  RenderOptions& render) {
  std::printf("[1/4] importing %s\n", scenePath.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  TriangleScene scene = loadLayout(scenePath);
  const double loadSeconds = secondsSince(t0);
  if (const std::size_t n = useOwnLights(render, scene.lights, scenePath.string()))
    std::printf("      lit by the scene's own %zu light(s)\n", n);
  const auto t1 = std::chrono::steady_clock::now();
  World world = meshToWorld(scene, defaultVoxelSize(scene), ImportLimits{});
  const double sdfSeconds = secondsSince(t1);
  writeWorld(world, out / "world");
  world = readWorld(out / "world");
  std::printf("      %zu triangles -> %zu bricks (voxel %.4f m) in %.2f s\n",
              scene.triangles.size(), world.bricks.size(), world.voxelSize,
              loadSeconds + sdfSeconds);
  report.scene = scenePath.string();
  report.triangles = scene.triangles.size();
  report.bricks = world.bricks.size();
  report.voxelSize = world.voxelSize;
  report.importSeconds = loadSeconds + sdfSeconds;
  return world;
}

// Front, right and above, each framing the world's bounds.
std::vector<DemoView> sceneViews(const World& world) {
  std::vector<DemoView> views;
  for (auto [name, from] : {std::pair<const char*, glm::dvec3>{"front", {0.15, 0.35, 1.0}},
                            {"right", {1.0, 0.5, 0.35}},
                            {"above", {-0.35, 1.4, 0.6}}}) {
    Camera cam = frameBounds(world.worldMin(), world.worldMax(), from, 45.0);
    // The bounding sphere is loose for a flat scene: move in so the content fills the frame.
    cam.position = cam.target + (cam.position - cam.target) * 0.6;
    views.push_back({name, cam});
  }
  return views;
}

void writeViewPngs(const fs::path& out, const std::string& name, const ViewResult& r) {
  writePng(out / ("view-" + name + ".png"), r.image);
  writePng(out / ("view-" + name + "-direct.png"), r.directImage);
  writePng(out / ("view-" + name + "-indirect.png"), r.indirectImage);
}

void printView(const fs::path& png, const ViewResult& r, bool gi) {
  std::printf("      %s: %zu/%zu rays hit, shade %.1f ms", png.c_str(), r.hits, r.rays,
              r.shadeMilliseconds);
  if (r.objectHits) std::printf(" (%zu pixels on moving objects)", r.objectHits);
  if (gi && !r.probeMilliseconds.empty())
    std::printf(", %zu GI frames (%.0f ms/frame, converged after %d), queries %.1f ms",
                r.probeMilliseconds.size(), mean(r.probeMilliseconds), r.framesToConverge,
                r.sampleMilliseconds);
  std::printf("\n");
  if (r.nonFinite) std::printf("      warning: %zu pixels had non-finite radiance\n", r.nonFinite);
}

// A rendered view's PNGs, its report rows and its console line.
void emitView(const fs::path& out, const std::string& name, const ViewResult& r, bool gi,
              DemoTables& tables) {
  writeViewPngs(out, name, r);
  tables.addView(name, r, gi);
  printView(out / ("view-" + name + ".png"), r, gi);
}

ObjectViewStats objectViewStats(const DemoObjects& objects, const ViewResult& r) {
  ObjectViewStats s;
  s.instances = objects.instances.size();
  s.pixels = r.objectHits;
  s.regionMilliseconds = r.objectMilliseconds;
  s.probeRays = r.objectRays;
  s.probeRayHits = r.objectRayHits;
  return s;
}

// Renders the views of one world and appends their report rows; then, with `objects`, the
// objectViews with the objects moving for kObjectGiFrames more GI frames (the last one's stats
// into *objectStats).
// *objectView (optional) gets the last objects view's result.
void renderViews(const World& world, gpu::Context* context, const RenderOptions& options,
                 const std::vector<DemoView>& views, const fs::path& out, int width, int height,
                 DemoTables& tables, DemoObjects* objects = nullptr,
                 const std::vector<DemoView>& objectViews = {},
                 std::optional<ObjectViewStats>* objectStats = nullptr,
                 ViewResult* objectView = nullptr) {
  ViewRenderer renderer(world, context, options);
  std::vector<DemoView> all = views;
  if (objects) all.insert(all.end(), objectViews.begin(), objectViews.end());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const DemoView& v = all[i];
    if (objects && i == views.size()) renderer.setObjects(objects, kObjectGiFrames);
    ViewResult r = renderer.render(v.camera, width, height);
    if (objects && i >= views.size() && objectStats) *objectStats = objectViewStats(*objects, r);
    emitView(out, v.name, r, options.gi, tables);
    if (objects && i >= views.size() && objectView) *objectView = std::move(r);
  }
}

// The objects view again with the objects' cards off (same scripted motion, a fresh renderer):
// view-objects-card-bounce.png shows what the cards add to the indirect light, and the report
// the mean indirect irradiance both ways.
void renderCardBounce(const World& world, gpu::Context* context, const RenderOptions& options,
                      const DemoView& view, const ViewResult& cardsOn, const fs::path& out,
                      int width, int height, DemoTables& tables, DemoReport& report) {
  RenderOptions off = options;
  off.renderer.settings.objects.cards = false;
  std::unique_ptr<DemoObjects> objects = demoSceneObjects();
  ViewRenderer renderer(world, context, off);
  renderer.render(view.camera, width, height);  // the static warm-up, as before view `objects`
  renderer.setObjects(objects.get(), kObjectGiFrames);
  const ViewResult cardsOff = renderer.render(view.camera, width, height);
  emitView(out, "objects-no-cards", cardsOff, off.gi, tables);
  writePng(out / "view-objects-card-bounce.png",
           addedLight(cardsOn.indirectImage, cardsOff.indirectImage, 16.0f));
  if (!cardsOn.convergence.empty() && !cardsOff.convergence.empty()) {
    report.indirectCardsOn = cardsOn.convergence.back();
    report.indirectCardsOff = cardsOff.convergence.back();
  }
}

// The Cornell box lit by its own light only, as one more view; returns the report's line.
std::string renderCornell(const DemoOptions& o, gpu::Context* context, DemoTables& tables) {
  if (!o.cornell) {
    std::printf("[3/4] Cornell box: skipped (--cornell off)\n");
    return "skipped (--cornell off)";
  }
  const fs::path& cornell = *o.cornell;
  if (!fs::exists(cornell)) {
    std::printf(
        "[3/4] Cornell box: skipped, %s is absent (../shared/data only exists in dev "
        "checkouts and CI)\n",
        cornell.c_str());
    return "skipped: " + cornell.string() + " is absent";
  }
  std::printf("[3/4] Cornell box: %s\n", cornell.c_str());
  TriangleScene box = loadGltf(cornell);
  RenderOptions boxOptions = o.render;
  // The box's own light only: no sun, black sky (the open front looks into the dark).
  boxOptions.lights = SceneLights{};
  // The real light is flush with the ceiling, which never occludes it; the default penumbra
  // (k = 16) would read the ceiling the shadow rays graze near the light as a soft occluder
  // and band the walls. k = 64 keeps the boxes' shadows soft but the ceiling out of them.
  boxOptions.lights.lights.push_back(cornellSpotFromEmitters(box, 64.0f));
  boxOptions.exposureStops = o.cornellExposureStops;
  World boxWorld = meshToWorld(box, defaultVoxelSize(box), ImportLimits{});
  const glm::dvec3 lo = boxWorld.worldMin(), hi = boxWorld.worldMax(), mid = 0.5 * (lo + hi);
  Camera cam;
  cam.target = mid;
  cam.position = mid + glm::dvec3(0.0, 0.0, 3.9 * 0.5 * (hi.y - lo.y));
  cam.fovYDegrees = 40.0;
  renderViews(boxWorld, context, boxOptions, {{"cornell", cam}}, o.out, o.width, o.height, tables);
  const SceneLight& spot = boxOptions.lights.lights.front();
  char line[256];
  std::snprintf(line, sizeof line,
                "%s: ceiling light as a downward spot light of intensity Ke·A = %.3f (quad "
                "emission removed), black sky, exposure %+.1f EV",
                cornell.filename().c_str(), spot.intensity, boxOptions.exposureStops);
  return line;
}

}  // namespace

int runDemo(const DemoOptions& o) {
  fs::create_directories(o.out);
  DemoReport report;
  report.width = o.width;
  report.height = o.height;
  report.objectGiFrames = kObjectGiFrames;
  RenderOptions render = o.render;
  const World world =
      importScene(o.scene.empty() ? findDefaultScene() : o.scene, o.out, report, render);
  report.options = render;

  std::unique_ptr<gpu::Context> context = o.device ? gpu::Context::create(*o.device) : nullptr;
  report.device = context ? context->deviceName() : "CPU reference";
  std::printf(
      "[2/4] rendering on %s, GI %s (%d GI frames before the first view, %u rays per "
      "probe)\n",
      report.device.c_str(), render.gi ? "on" : "off", render.giFrames,
      render.renderer.settings.probes.raysPerProbe);
  const std::vector<DemoView> views = sceneViews(world);
  DemoTables tables;
  const auto t2 = std::chrono::steady_clock::now();
  // The objects view: the front camera again, after the objects moved for a few GI frames.
  std::unique_ptr<DemoObjects> objects = o.objects ? demoSceneObjects() : nullptr;
  ViewResult objectView;
  renderViews(world, context.get(), render, views, o.out, o.width, o.height, tables, objects.get(),
              {{"objects", views.front().camera}}, &report.objects, &objectView);
  if (objects && render.gi && render.renderer.settings.objects.cards)
    renderCardBounce(world, context.get(), render, {"objects", views.front().camera}, objectView,
                     o.out, o.width, o.height, tables, report);
  report.sceneRenderSeconds = secondsSince(t2);

  report.cornell = renderCornell(o, context.get(), tables);

  std::printf("[4/4] writing %s\n", (o.out / "report.md").c_str());
  const std::string text = demoReport(report, tables);
  writeFileAtomically(o.out / "report.md", text.data(), text.size());
  return 0;
}

}  // namespace sdfstream
