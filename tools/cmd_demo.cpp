#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "gpu/context.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/cornell_light.h"
#include "tools/view_renderer.h"
#include "world/gltf_import.h"
#include "world/mesh_to_sdf.h"
#include "world/scene_layout.h"
#include "world/world_io.h"

namespace fs = std::filesystem;

namespace sdfstream::cli {
namespace {
double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / double(v.size());
}

struct DemoView {
  std::string name;
  Camera camera;
};

// GI frames the objects view runs with its objects moving, after the static views converged the
// probes: enough for the probes around them to follow (vigilant probes blend fast), few enough
// to keep scripts/demo's time (about 1 s each on lavapipe).
constexpr int kObjectGiFrames = 12;

// What the report says about the moving objects of the objects view.
struct ObjectViewStats {
  std::size_t instances = 0, pixels = 0;
  double regionMilliseconds = 0.0;
  std::uint32_t probeRays = 0, probeRayHits = 0;
};

// Renders the views of one world and appends their report rows; then, with `objects`, the
// objectViews with the objects moving for kObjectGiFrames more GI frames.
void renderViews(const World& world, gpu::Context* context, const RenderOptions& options,
                 const std::vector<DemoView>& views, const fs::path& outDir, int width, int height,
                 std::ostringstream& rows, std::ostringstream& gi, std::ostringstream& convergence,
                 DemoObjects* objects = nullptr, const std::vector<DemoView>& objectViews = {},
                 ObjectViewStats* objectStats = nullptr) {
  ViewRenderer renderer(world, context, options);
  std::vector<DemoView> all = views;
  if (objects) all.insert(all.end(), objectViews.begin(), objectViews.end());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const DemoView& v = all[i];
    if (objects && i == views.size()) renderer.setObjects(objects, kObjectGiFrames);
    ViewResult r = renderer.render(v.camera, width, height);
    if (objects && i >= views.size() && objectStats) {
      objectStats->instances = objects->instances.size();
      objectStats->pixels = r.objectHits;
      objectStats->regionMilliseconds = r.objectMilliseconds;
      objectStats->probeRays = r.objectRays;
      objectStats->probeRayHits = r.objectRayHits;
    }
    const fs::path png = outDir / ("view-" + v.name + ".png");
    writePng(png, r.image);
    writePng(outDir / ("view-" + v.name + "-direct.png"), r.directImage);
    writePng(outDir / ("view-" + v.name + "-indirect.png"), r.indirectImage);
    rows << "| " << v.name << " | shade_primary (trace + direct light) | " << r.shadeMilliseconds
         << " | " << (r.rays / (r.shadeMilliseconds * 1e3)) << " |\n";
    if (options.gi) {
      rows << "| " << v.name << " | probe_sample (" << r.hits << " hit pixels) | "
           << r.sampleMilliseconds << " | |\n";
      if (!r.probeMilliseconds.empty()) {
        gi << "| " << v.name << " | " << r.probeMilliseconds.size() << " | "
           << mean(r.probeMilliseconds) << " | "
           << *std::max_element(r.probeMilliseconds.begin(), r.probeMilliseconds.end()) << " | "
           << r.probeMilliseconds.back() << " | " << r.lightMilliseconds << " | "
           << r.framesToConverge << " |";
        for (const auto& p : r.probePasses) gi << " " << p.name << " " << p.milliseconds << ";";
        gi << " |\n";
        convergence << "| " << v.name << " |";
        for (const glm::vec3& e : r.convergence) convergence << " " << luminance(e);
        convergence << " |\n";
      } else {
        gi << "| " << v.name << " | 0 (probes of the previous view reused) | | | | | | |\n";
      }
    }
    std::printf("      %s: %zu/%zu rays hit, shade %.1f ms", png.c_str(), r.hits, r.rays,
                r.shadeMilliseconds);
    if (r.objectHits) std::printf(" (%zu pixels on moving objects)", r.objectHits);
    if (options.gi && !r.probeMilliseconds.empty())
      std::printf(", %zu GI frames (%.0f ms/frame, converged after %d), queries %.1f ms",
                  r.probeMilliseconds.size(), mean(r.probeMilliseconds), r.framesToConverge,
                  r.sampleMilliseconds);
    std::printf("\n");
    if (r.nonFinite)
      std::printf("      warning: %zu pixels had non-finite radiance\n", r.nonFinite);
  }
}
}  // namespace

int runDemo(int argc, char** argv) {
  Args args(argc, argv, 2,
            renderValueOptions(
                {"-o", "--scene", "--device", "--width", "--height", "--cornell", "--objects"}),
            {"--help", "-h", "--cpu"});
  if (args.has("--help") || args.has("-h")) {
    std::printf(
        "usage: sdfstream demo [-o DIR] [--scene LAYOUT.json] [options]\n"
        "\n"
        "Imports the built-in scene (Debian's glmark2 bunny and assimp test models on a ground\n"
        "slab between a red and a green wall, demo/default_scene.json), converges the GI probes\n"
        "and renders three views lit by a sun and a gradient sky, plus the Cornell box when\n"
        "../shared/data/cornell-box exists. Per view NAME: DIR/view-NAME.png (direct + indirect\n"
        "light), view-NAME-direct.png (direct only) and view-NAME-indirect.png (indirect only);\n"
        "then DIR/world/ and DIR/report.md (default DIR: out/demo). With moving objects (GPU\n"
        "only), a fourth view 'objects' repeats 'front' after a few GI frames with three scripted\n"
        "objects moving through the scene: compare view-objects-indirect.png with\n"
        "view-front-indirect.png for their indirect shadows.\n"
        "\n"
        "  --width W --height H              image size (default 640 x 480)\n"
        "  --objects on|off                  the objects view (default on; off with --cpu)\n"
        "  --cornell FILE|off                the Cornell box GLB (default ../shared/data/\n"
        "                                    cornell-box/CornellBox-Original.glb, or under\n"
        "                                    $SDFSTREAM_SHARED_DATA); off skips it\n"
        "%s%s"
        "  --device NAME | --cpu             GPU choice, or the CPU reference (direct light "
        "only)\n",
        kStillGiFramesHelp, kRenderHelp);
    return 0;
  }
  fs::path outDir = args.value("-o").value_or("out/demo");
  fs::path scenePath = args.value("--scene").value_or(SDFSTREAM_DEFAULT_SCENE);
  int width = args.integer("--width", 640, 16, 4096);
  int height = args.integer("--height", 480, 16, 4096);
  RenderOptions options = renderOptionsFromArgs(args, args.has("--cpu"), 24);
  const std::string objectsFlag =
      args.value("--objects").value_or(args.has("--cpu") ? "off" : "on");
  if (objectsFlag != "on" && objectsFlag != "off")
    throw InputError(InputErrorKind::Usage, "command line",
                     "--objects expects on or off, got '" + objectsFlag + "'");
  if (objectsFlag == "on" && args.has("--cpu"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "--objects on needs Vulkan (the CPU reference has no moving objects)");
  const char* dataEnv = std::getenv("SDFSTREAM_SHARED_DATA");
  fs::path cornell = args.value("--cornell")
                         .value_or((fs::path(dataEnv ? dataEnv : "../shared/data") / "cornell-box" /
                                    "CornellBox-Original.glb")
                                       .string());
  fs::create_directories(outDir);

  std::printf("[1/4] importing %s\n", scenePath.c_str());
  auto t0 = std::chrono::steady_clock::now();
  TriangleScene scene = loadLayout(scenePath);
  double loadSeconds = secondsSince(t0);
  auto t1 = std::chrono::steady_clock::now();
  World world = meshToWorld(scene, defaultVoxelSize(scene), ImportLimits{});
  double sdfSeconds = secondsSince(t1);
  writeWorld(world, outDir / "world");
  world = readWorld(outDir / "world");  // render what is on disk, checksums verified
  std::printf("      %zu triangles -> %zu bricks (voxel %.4f m) in %.2f s\n",
              scene.triangles.size(), world.bricks.size(), world.voxelSize,
              loadSeconds + sdfSeconds);

  std::unique_ptr<gpu::Context> context = gpuContextFromArgs(args);
  std::string device = context ? context->deviceName() : "CPU reference";
  std::printf(
      "[2/4] rendering on %s, GI %s (%d GI frames before the first view, %u rays per "
      "probe)\n",
      device.c_str(), options.gi ? "on" : "off", options.giFrames,
      options.renderer.settings.probes.raysPerProbe);
  std::vector<DemoView> views;
  for (auto [name, from] : {std::pair<const char*, glm::dvec3>{"front", {0.15, 0.35, 1.0}},
                            {"right", {1.0, 0.5, 0.35}},
                            {"above", {-0.35, 1.4, 0.6}}}) {
    Camera cam = frameBounds(world.worldMin(), world.worldMax(), from, 45.0);
    // The bounding sphere is loose for a flat scene: move in so the content fills the frame.
    cam.position = cam.target + (cam.position - cam.target) * 0.6;
    views.push_back({name, cam});
  }
  std::ostringstream rows, gi, convergence;
  auto t2 = std::chrono::steady_clock::now();
  // The objects view: the front camera again, after the objects moved for a few GI frames.
  std::unique_ptr<DemoObjects> objects = objectsFlag == "on" ? demoSceneObjects() : nullptr;
  ObjectViewStats objectStats;
  renderViews(world, context.get(), options, views, outDir, width, height, rows, gi, convergence,
              objects.get(), {{"objects", views.front().camera}}, &objectStats);
  const double sceneRenderSeconds = secondsSince(t2);

  std::string cornellLine;
  if (args.value("--cornell") == "off") {
    cornellLine = "skipped (--cornell off)";
    std::printf("[3/4] Cornell box: skipped (--cornell off)\n");
  } else if (!fs::exists(cornell)) {
    cornellLine = "skipped: " + cornell.string() + " is absent";
    std::printf(
        "[3/4] Cornell box: skipped, %s is absent (../shared/data only exists in dev "
        "checkouts and CI)\n",
        cornell.c_str());
  } else {
    std::printf("[3/4] Cornell box: %s\n", cornell.c_str());
    TriangleScene box = loadGltf(cornell);
    RenderOptions boxOptions = options;
    // The box's own light only: no sun, black sky (the open front looks into the dark).
    boxOptions.lights = SceneLights{};
    // The real light is flush with the ceiling, which never occludes it; the default penumbra
    // (k = 16) would read the ceiling the shadow rays graze near the light as a soft occluder
    // and band the walls. k = 64 keeps the boxes' shadows soft but the ceiling out of them.
    boxOptions.lights.lights.push_back(cornellSpotFromEmitters(box, 64.0f));
    if (!args.value("--exposure")) boxOptions.exposureStops = 1.5f;
    World boxWorld = meshToWorld(box, defaultVoxelSize(box), ImportLimits{});
    const glm::dvec3 lo = boxWorld.worldMin(), hi = boxWorld.worldMax(), mid = 0.5 * (lo + hi);
    Camera cam;
    cam.target = mid;
    cam.position = mid + glm::dvec3(0.0, 0.0, 3.9 * 0.5 * (hi.y - lo.y));
    cam.fovYDegrees = 40.0;
    renderViews(boxWorld, context.get(), boxOptions, {{"cornell", cam}}, outDir, width, height,
                rows, gi, convergence);
    const SceneLight& spot = boxOptions.lights.lights.front();
    char line[256];
    std::snprintf(line, sizeof line,
                  "%s: ceiling light as a downward spot light of intensity Ke·A = %.3f (quad "
                  "emission removed), black sky, exposure %+.1f EV",
                  cornell.filename().c_str(), spot.intensity, boxOptions.exposureStops);
    cornellLine = line;
  }

  std::printf("[4/4] writing %s\n", (outDir / "report.md").c_str());
  const SceneLight* sun = options.lights.lights.empty() ? nullptr : &options.lights.lights[0];
  std::ostringstream report;
  report << "# sdfstream demo report\n\n"
         << "| item | value |\n|---|---|\n"
         << "| scene | " << scenePath.string() << " |\n"
         << "| device | " << device << " |\n"
         << "| triangles | " << scene.triangles.size() << " |\n"
         << "| voxel size | " << world.voxelSize << " m |\n"
         << "| bricks in world | " << world.bricks.size() << " (all resident in one cascade) |\n"
         << "| import time (load + mesh to SDF bricks) | " << loadSeconds + sdfSeconds << " s |\n"
         << "| import time per million triangles | "
         << (loadSeconds + sdfSeconds) / (double(scene.triangles.size()) / 1e6) << " s |\n"
         << "| image size | " << width << " x " << height << " |\n"
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
         << "| Cornell box | " << cornellLine << " |\n"
         << "| wall time of the three scene views (GI frames included) | " << sceneRenderSeconds
         << " s |\n\n"
         << "Each view NAME has view-NAME.png (final), view-NAME-direct.png and "
            "view-NAME-indirect.png (the two parts of the final image, tone-mapped alike).\n\n"
         << "## Per-pass GPU times\n\n| view | pass | ms | MRays/s |\n|---|---|---|---|\n"
         << rows.str() << "\n";
  if (options.gi)
    report << "## GI frames\n\nProbe update GPU time per frame (classify, select, trace + shade, "
              "blend, borders; the hit cache makes later frames cheaper), the light cache (run "
              "when the lights or pages change: the first frame), and the frames after which "
              "the mean indirect irradiance over a fixed subset of the view's hit pixels stays "
              "within 2% of its final value.\n\n"
              "| view | GI frames | probe ms mean | probe ms max | probe ms last | light cache ms "
              "| frames to converge | last frame's passes (ms) |\n"
              "|---|---|---|---|---|---|---|---|\n"
           << gi.str()
           << "\nMean indirect irradiance (luminance) over the subset after each GI frame:\n\n"
              "| view | frame 1, 2, ... |\n|---|---|\n"
           << convergence.str() << "\n";
  if (objects) {
    report << "## Moving objects\n\nView `objects` is view `front` after " << kObjectGiFrames
           << " more GI frames (" << kObjectGiFrames / 30.0
           << " s of scripted motion at 30 frames per second) with " << objectStats.instances
           << " moving objects (a sphere circling 0.4 m above the ground, a cube dropping onto it, "
              "a flat box driving a loop): they cast hard shadows in view-objects-direct.png, and "
              "the probes trace them, so view-objects-indirect.png is darker than "
              "view-front-indirect.png under and beside them (their indirect shadows).\n\n"
           << "| item | value |\n|---|---|\n"
           << "| pixels on objects | " << objectStats.pixels << " |\n"
           << "| object region passes, all " << kObjectGiFrames << " GI frames | "
           << objectStats.regionMilliseconds << " ms |\n"
           << "| last GI frame: probe rays that searched the objects / hit one | "
           << objectStats.probeRays << " / " << objectStats.probeRayHits << " |\n\n";
  }
  report << "Absolute times mean something only on a real GPU; on lavapipe they measure the CPU.\n";
  std::string text = report.str();
  writeFileAtomically(outDir / "report.md", text.data(), text.size());
  return 0;
}

}  // namespace sdfstream::cli
