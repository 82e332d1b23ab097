// sdfstream fly: drives a camera along a path over a world pack, streaming its tiles into the
// cascade stack without ever waiting on disk, updates the GI core on the streamed stack every
// frame, renders frames shaded with direct + indirect light, and writes streaming and GI metrics.
// Scripted moving objects (issue 7) spread along the path move every frame; the GI traces them,
// so they cast direct and indirect shadows on the streamed world.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "demo/fly_path.h"
#include "demo/frame_image.h"
#include "demo/gi_shading.h"
#include "demo/moving_objects.h"
#include "demo/plot.h"
#include "gi/camera.h"
#include "gpu/context.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/stream_metrics.h"
#include "tools/args.h"
#include "tools/commands.h"
#include "tools/view_renderer.h"

namespace fs = std::filesystem;

namespace sdfstream::cli {
namespace {

void writePlots(const fs::path& dir, const std::vector<FrameMetrics>& frames) {
  static const glm::vec3 kColors[] = {{0.85f, 0.1f, 0.1f}, {0.1f, 0.45f, 0.85f}, {0.1f, 0.6f, 0.2f},
                                      {0.8f, 0.5f, 0.0f},  {0.5f, 0.2f, 0.7f},   {0.3f, 0.3f, 0.3f},
                                      {0.0f, 0.6f, 0.6f},  {0.6f, 0.4f, 0.3f}};
  Chart residency{"Residency per cascade", "frame", "resident / required bricks", {}};
  int cascades = frames.empty() ? 0 : int(frames.front().stream.cascades.size());
  for (int c = 0; c < cascades; ++c) {
    Series s{"cascade " + std::to_string(c), {}, {}, kColors[c % 8]};
    for (const auto& f : frames) {
      const auto& cs = f.stream.cascades[c];
      s.x.push_back(f.frame);
      s.y.push_back(cs.requiredBricks ? double(cs.residentBricks) / cs.requiredBricks : 1.0);
    }
    residency.series.push_back(std::move(s));
  }
  writeChartPng(dir / "residency.png", residency);

  Chart bytes{"Bytes streamed per frame", "frame", "MiB", {}};
  Series read{"read from disk", {}, {}, kColors[0]}, decoded{"decoded", {}, {}, kColors[1]},
      uploaded{"uploaded to the atlas", {}, {}, kColors[2]};
  const LoaderStats* prev = nullptr;
  for (const auto& f : frames) {
    double r = double(f.loader.bytesRead - (prev ? prev->bytesRead : 0)) / (1 << 20);
    double d = double(f.loader.bytesDecoded - (prev ? prev->bytesDecoded : 0)) / (1 << 20);
    read.x.push_back(f.frame), read.y.push_back(r);
    decoded.x.push_back(f.frame), decoded.y.push_back(d);
    uploaded.x.push_back(f.frame), uploaded.y.push_back(double(f.stream.bytesUploaded) / (1 << 20));
    prev = &f.loader;
  }
  bytes.series = {read, decoded, uploaded};
  writeChartPng(dir / "bytes.png", bytes);
}

// Exposure added to the indirect-only layer of --layers (stops).
constexpr float kIndirectLayerStops = 2.0f;

// GI cost of one frame (gi.csv): the passes GiRenderer ran.
struct GiFrameMetrics {
  int frame = 0;
  GiFrameStats gi;
  std::vector<gpu::PassTiming> probePasses;
  double shadeMilliseconds = 0.0;   // 0 when the frame was not rendered
  double sampleMilliseconds = 0.0;  // 0 when the frame was not rendered
  std::size_t objectPixels = 0;     // rendered frames: pixels showing a moving object
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, std::size_t(p * double(v.size() - 1) + 0.5))];
}

void writeGiCsv(const fs::path& file, const std::vector<GiFrameMetrics>& frames) {
  std::string csv =
      "frame,light_ms,probe_ms,pages_relit,probes_updated,rays_traced,rays_cached,shade_ms,"
      "sample_ms,object_instances,object_region_ms,object_pages_relit,object_rays,object_hits,"
      "object_steps,object_pixels";
  // The probe update's passes one by one, named as ProbeField::lastTimings names them (the union
  // over all frames, in order of first appearance, so the columns stay fixed within a file).
  std::vector<std::string> passes;
  for (const auto& f : frames)
    for (const auto& t : f.probePasses)
      if (std::find(passes.begin(), passes.end(), t.name) == passes.end()) passes.push_back(t.name);
  for (const std::string& p : passes) csv += "," + p + "_ms";
  csv += "\n";
  char row[256];
  for (const auto& f : frames) {
    std::snprintf(row, sizeof row, "%d,%.3f,%.3f,%u,%u,%u,%u,%.3f,%.3f,%u,%.3f,%u,%u,%u,%u,%zu",
                  f.frame, f.gi.lightMilliseconds, f.gi.probeMilliseconds, f.gi.pagesRelit,
                  f.gi.probes.probesUpdated, f.gi.probes.raysTraced, f.gi.probes.raysCached,
                  f.shadeMilliseconds, f.sampleMilliseconds, f.gi.objectInstances,
                  f.gi.objectMilliseconds, f.gi.objectPagesRelit, f.gi.probes.objectRays,
                  f.gi.probes.objectHits, f.gi.probes.objectSteps, f.objectPixels);
    csv += row;
    for (const std::string& p : passes) {
      double ms = 0.0;
      for (const auto& t : f.probePasses)
        if (t.name == p) ms += t.milliseconds;
      std::snprintf(row, sizeof row, ",%.3f", ms);
      csv += row;
    }
    csv += "\n";
  }
  writeFileAtomically(file, csv.data(), csv.size());
}

std::string giSummaryMarkdown(const std::vector<GiFrameMetrics>& frames, bool gi,
                              const probe::ProbeFieldSettings& probes, std::size_t probeBytes) {
  std::vector<double> probe, light, shade, sample, updated, traced;
  for (const auto& f : frames) {
    probe.push_back(f.gi.probeMilliseconds);
    light.push_back(f.gi.lightMilliseconds);
    updated.push_back(f.gi.probes.probesUpdated);
    traced.push_back(f.gi.probes.raysTraced);
    if (f.shadeMilliseconds > 0.0) shade.push_back(f.shadeMilliseconds);
    if (f.sampleMilliseconds > 0.0) sample.push_back(f.sampleMilliseconds);
  }
  auto mean = [](const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / double(v.size());
  };
  char text[2048];
  if (!gi) {
    std::snprintf(text, sizeof text,
                  "\n## GI\n\nOff (--gi off or --cpu): frames show direct light only. Shade pass "
                  "(trace + direct light; GPU time, or wall time of the CPU reference) of rendered "
                  "frames: mean %.2f ms, p99 %.2f ms.\n",
                  mean(shade), percentile(shade, 0.99));
    return text;
  }
  std::snprintf(
      text, sizeof text,
      "\n## GI\n\nGPU time per frame (gi.csv has every frame): the light cache relights pages "
      "that streamed in or changed; the probe field (one 17^3 volume per cascade, %u rays per "
      "probe, %.1f MiB) updates within its ray budget of %u rays per frame.\n\n"
      "| pass | mean ms | p50 ms | p99 ms | max ms |\n|---|---|---|---|---|\n"
      "| light cache | %.2f | %.2f | %.2f | %.2f |\n"
      "| probe update (all passes) | %.2f | %.2f | %.2f | %.2f |\n"
      "| shade_primary (rendered frames) | %.2f | %.2f | %.2f | %.2f |\n"
      "| probe_sample (rendered frames) | %.2f | %.2f | %.2f | %.2f |\n\n"
      "Probes updated per frame: mean %.0f; probe rays sphere-traced per frame: mean %.0f (the "
      "rest come from the hit cache).\n",
      probes.raysPerProbe, double(probeBytes) / (1 << 20), probes.rayBudget, mean(light),
      percentile(light, 0.5), percentile(light, 0.99), percentile(light, 1.0), mean(probe),
      percentile(probe, 0.5), percentile(probe, 0.99), percentile(probe, 1.0), mean(shade),
      percentile(shade, 0.5), percentile(shade, 0.99), percentile(shade, 1.0), mean(sample),
      percentile(sample, 0.5), percentile(sample, 0.99), percentile(sample, 1.0), mean(updated),
      mean(traced));
  return text;
}

// The moving objects' share of the frame (empty without objects).
std::string objectSummaryMarkdown(const std::vector<GiFrameMetrics>& frames, bool gi) {
  std::vector<double> regions, relit, rays, hits, pixels;
  std::uint32_t instances = 0;
  for (const auto& f : frames) {
    instances = std::max(instances, f.gi.objectInstances);
    regions.push_back(f.gi.objectMilliseconds);
    relit.push_back(f.gi.objectPagesRelit);
    rays.push_back(f.gi.probes.objectRays);
    hits.push_back(f.gi.probes.objectHits);
    if (f.shadeMilliseconds > 0.0) pixels.push_back(double(f.objectPixels));
  }
  if (instances == 0) return {};
  auto mean = [](const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / double(v.size());
  };
  char text[1024];
  std::snprintf(
      text, sizeof text,
      "\n## Moving objects\n\n%u scripted objects along the path (--objects), moved every frame. "
      "Region lists (object_regions passes): mean %.2f ms, p99 %.2f ms per frame; light-cache "
      "pages relit because objects moved: mean %.0f per frame (inside the light cache time "
      "above); probe rays that searched the objects: mean %.0f per frame, of which %.0f hit one%s; "
      "pixels showing an object in the rendered frames: mean %.0f. Their search in primary "
      "rays and shadow rays is inside shade_primary's time (gi.csv has every frame).\n",
      instances, mean(regions), percentile(regions, 0.99), mean(relit), mean(rays), mean(hits),
      gi ? "" : " (GI off: none)", mean(pixels));
  return text;
}

}  // namespace

int runFly(int argc, char** argv) {
  Args args(argc, argv, 2,
            renderValueOptions({"-o", "--path", "--speed", "--frames", "--width", "--height",
                                "--image-every", "--cascades", "--atlas-mib", "--upload-mib",
                                "--device", "--loader-threads", "--objects"}),
            {"--help", "-h", "--cpu", "--no-pacing", "--layers"});
  if (args.has("--help") || args.has("-h")) {
    std::printf(
        "usage: sdfstream fly WORLD -o DIR [options]\n"
        "\n"
        "Flies a camera over a world pack (headless), streaming tiles into camera-centred\n"
        "cascades without waiting on disk, and updates the GI (light cache + one probe volume\n"
        "per cascade) on the streamed stack every frame. Frames are shaded with direct +\n"
        "indirect light; scripted moving objects (--objects) move every frame and the GI sees\n"
        "them. Writes DIR/frames/frame-NNNN.png, DIR/metrics.csv, DIR/gi.csv (GI pass times and\n"
        "object counts per frame), DIR/summary.md, DIR/residency.png and DIR/bytes.png.\n"
        "\n"
        "  --path FILE        waypoints, one 'x y z' per line (default: a route across the world)\n"
        "  --speed M/S        camera speed (default 80 m/s, a fast fly-over)\n"
        "  --no-pacing        run frames back to back instead of at 30 per wall-clock second\n"
        "  --frames N         frames at 30 per second of path time (default 300)\n"
        "  --width W --height H   frame size (default 320 x 180)\n"
        "  --image-every K    write every K-th frame as PNG (default frames/6)\n"
        "  --layers           also write frame-NNNN-direct.png and frame-NNNN-indirect.png\n"
        "                     (direct light only; indirect light only, 2 stops brighter: the\n"
        "                     objects' indirect shadows are easiest to see there)\n"
        "  --cascades N       cascades (default 6, at most the pack's LOD count)\n"
        "  --atlas-mib N      shared brick atlas budget (default 96)\n"
        "  --upload-mib N     brick bytes uploaded per frame at most (default 16)\n"
        "  --loader-threads N tile loader threads (default 2)\n"
        "  --objects N        scripted moving objects spread along the path (default 150, 0 =\n"
        "                     none; boxes and spheres of 1-4 m, every 6th 8-14 m, hovering in\n"
        "                     circles, falling and driving loops on the ground beside the\n"
        "                     path; Vulkan only). They cast direct and indirect shadows.\n"
        "  --gi-frames N                     GI frames at the start of the path before the flight\n"
        "                                    (default 0; they stream too, outside metrics.csv)\n"
        "%s"
        "  --device NAME | --cpu   GPU choice, or trace with the CPU reference (direct light "
        "only)\n",
        kRenderHelp);
    return 0;
  }
  if (args.positional().size() != 1 || !args.value("-o"))
    throw InputError(InputErrorKind::Usage, "command line",
                     "expected: sdfstream fly WORLD -o DIR (see --help)");
  fs::path world = args.positional()[0];
  fs::path out = *args.value("-o");
  PackTileStore store(world);
  const PackManifest& manifest = store.manifest();
  FlyPath path = args.value("--path") ? readFlyPath(*args.value("--path"))
                                      : defaultFlyPath(manifest.boundsMin, manifest.boundsMax);
  int frames = args.integer("--frames", 300, 1, 100000);
  double length = path.length();
  double speed = args.number("--speed", 80.0);
  int width = args.integer("--width", 320, 16, 4096), height = args.integer("--height", 180, 16, 4096);
  int imageEvery = args.integer("--image-every", std::max(1, frames / 6), 1, 100000);
  std::unique_ptr<gpu::Context> context = gpuContextFromArgs(args);
  // On a CPU Vulkan device (lavapipe) a full probe update of six cascades takes ~16 s a frame:
  // the ray budget keeps a fly-through to about a second a frame there (updates rotate through
  // the probes, nearest and in-view first).
  const std::uint32_t defaultBudget = context && context->isSoftware() ? 1u << 16 : 1u << 21;
  RenderOptions render = renderOptionsFromArgs(args, args.has("--cpu"), 0, defaultBudget);
  const int warmup = args.value("--gi-frames") ? render.giFrames : 0;
  const bool cpu = args.has("--cpu");
  const int objectCount = args.integer("--objects", cpu ? 0 : 150, 0, 100000);
  if (cpu && objectCount > 0)
    throw InputError(InputErrorKind::Usage, "command line",
                     "--objects needs Vulkan (the CPU reference has no moving objects); drop --cpu");

  StreamingOptions so;
  so.cascades = args.integer("--cascades", 6, 1, 8);
  const std::size_t slotBytes = 4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);
  so.atlasSlots = std::uint32_t(args.number("--atlas-mib", 96.0) * double(1 << 20) / slotBytes);
  so.uploadBytesPerFrame = std::size_t(args.number("--upload-mib", 16.0) * double(1 << 20));
  LoaderOptions lo;
  lo.threads = args.integer("--loader-threads", 2, 1, 64);
  TileLoader loader(store, lo);
  CascadeStack stack(store, loader, so);

  std::unique_ptr<GiRenderer> renderer =
      context ? std::make_unique<GiRenderer>(*context, render.renderer,
                                             std::uint32_t(stack.cascadeCount()))
              : nullptr;
  // The objects spread over the stretch the camera flies, from a little ahead of its start to
  // a little beyond its end (the camera looks ahead and down), on the pack's ground.
  std::unique_ptr<DemoObjects> objects;
  if (renderer && objectCount > 0) {
    PackGround ground(store, manifest.boundsMin.y, manifest.boundsMax.y);
    FlyObjectsSettings os;
    os.count = std::uint32_t(objectCount);
    os.sBegin = std::min(15.0, length);
    os.sEnd = std::min(length, speed * (frames - 1) / 30.0 + 90.0);
    objects = flyObjects(ground, path, os);
    renderer->setObjects(&objects->library, &objects->instances);
  }
  fs::create_directories(out / "frames");
  std::printf(
      "fly: %s, %d frames along %.0f m at %.1f m/s, %d cascades, atlas %.0f MiB, GI %s "
      "(%u probe rays per frame), %zu moving objects, on %s\n",
      world.c_str(), frames, length, speed, stack.cascadeCount(),
      double(stack.atlasBytes()) / (1 << 20), render.gi ? "on" : "off",
      render.renderer.settings.probes.rayBudget, objects ? objects->instances.size() : 0,
      context ? context->deviceName().c_str() : "CPU reference");

  auto cameraAt = [&](double s) {
    Camera cam;
    cam.position = path.position(s);
    glm::dvec3 dir = path.direction(s);
    cam.target = cam.position + glm::normalize(dir + glm::dvec3(0.0, -0.25, 0.0)) * 10.0;
    cam.fovYDegrees = 60.0;
    return cam;
  };
  std::uint64_t giFrame = 0;
  // One GI frame on the stack as it stands: sync the atlas slots the stack rewrote, relight,
  // update the probes.
  auto giUpdate = [&](const Camera& cam) {
    std::vector<std::uint32_t> dirty = stack.takeDirtySlots();
    if (!renderer) return GiFrameStats{};
    probe::ProbeFrameInputs inputs;
    inputs.cameraWorld = cam.position;
    inputs.viewDirection = glm::vec3(glm::normalize(cam.target - cam.position));
    return renderer->update(stack, dirty, render.lights, inputs, giFrame++);
  };
  for (int w = 0; w < warmup; ++w) {
    const Camera cam = cameraAt(0.0);
    if (objects) objects->apply(0.0);
    stack.update(cam.position, glm::normalize(cam.target - cam.position));
    giUpdate(cam);
  }
  if (warmup > 0) loader.takeStats();

  std::vector<FrameMetrics> metrics;
  std::vector<GiFrameMetrics> giMetrics;
  // Frames are paced at 30 per wall-clock second (unless --no-pacing) so the loader threads get
  // the same real time per frame as they would in an interactive application.
  const auto start = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    double seconds = f / 30.0;
    if (!args.has("--no-pacing"))
      std::this_thread::sleep_until(start + std::chrono::microseconds(std::int64_t(seconds * 1e6)));
    const Camera cam = cameraAt(speed * seconds);

    FrameMetrics m;
    m.frame = f;
    m.seconds = seconds;
    m.camera = cam.position;
    auto t0 = std::chrono::steady_clock::now();
    m.stream = stack.update(cam.position, glm::normalize(cam.target - cam.position));
    m.updateMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    GiFrameMetrics g;
    g.frame = f;
    if (objects) objects->apply(seconds);  // the GI update below consumes the moves
    g.gi = giUpdate(cam);
    if (renderer) g.probePasses = renderer->lastTimes().probePasses;
    m.gpuBytes = stack.atlasBytes() + std::size_t(stack.cascadeCount()) * layout::kCascadePageCount * 4;

    if (f % imageEvery == 0 || f == frames - 1) {
      CascadeStackImage img = stack.stackImage();
      HdrFrame frame;
      if (renderer) {
        frame = renderer->render(cam, width, height, img, render.lights);
        // The trace pass is now the shading pass: primary rays + their direct light.
        m.traceMilliseconds = renderer->lastTimes().shadeMilliseconds;
        g.shadeMilliseconds = m.traceMilliseconds;
        g.sampleMilliseconds = renderer->lastTimes().sampleMilliseconds;
        g.objectPixels = frame.objectHits;
      } else {
        auto rays = cameraRays(cam, width, height, img);
        const auto t1 = std::chrono::steady_clock::now();
        frame = composeFrame(shadePrimaryCpu(img, rays, toGpu(render.lights.lights, img),
                                             toGpu(render.lights.sky), render.renderer.shading, {}),
                             width, height, {}, {});
        g.shadeMilliseconds =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1)
                .count();
      }
      char name[64];
      std::snprintf(name, sizeof name, "frame-%04d.png", f);
      writePng(out / "frames" / name, toneMap(frame.final(), width, height, render.exposureStops));
      if (args.has("--layers")) {
        std::snprintf(name, sizeof name, "frame-%04d-direct.png", f);
        writePng(out / "frames" / name, toneMap(frame.direct, width, height, render.exposureStops));
        // Outdoors the indirect light is a few percent of the sun's: 2 stops brighter, so its
        // detail (the objects' indirect shadows) shows.
        std::snprintf(name, sizeof name, "frame-%04d-indirect.png", f);
        writePng(out / "frames" / name,
                 toneMap(frame.indirect, width, height, render.exposureStops + kIndirectLayerStops));
      }
    }
    giMetrics.push_back(g);
    m.loader = loader.takeStats();
    metrics.push_back(std::move(m));
    if (f % std::max(1, frames / 10) == 0 || f == frames - 1)
      std::fprintf(stderr, "  frame %d/%d: %u missing pages, %zu tiles cached\n", f + 1, frames,
                   metrics.back().stream.missingPages, metrics.back().loader.cachedTiles);
  }

  writeMetricsCsv(out / "metrics.csv", metrics);
  MetricsSummary summary = summarize(metrics);
  writeGiCsv(out / "gi.csv", giMetrics);
  const std::string giMd = giSummaryMarkdown(giMetrics, renderer && renderer->giEnabled(),
                                             render.renderer.settings.probes,
                                             renderer ? renderer->probeDeviceBytes() : 0) +
                           objectSummaryMarkdown(giMetrics, renderer && renderer->giEnabled());
  std::string md = "# Fly-through summary\n\nWorld: " + world.string() + "\n\n" +
                   summaryMarkdown(summary) + giMd;
  auto failed = loader.failedTiles();
  if (!failed.empty()) {
    md += "\nTiles that failed to load (reported, never treated as empty):\n";
    for (const TileKey& k : failed)
      md += "- tile " + std::to_string(k.coord.x) + "_" + std::to_string(k.coord.y) + "_" +
            std::to_string(k.coord.z) + " LOD " + std::to_string(k.lod) + "\n";
  }
  writeFileAtomically(out / "summary.md", md.data(), md.size());
  writePlots(out, metrics);
  std::printf(
      "fly: wrote %s (metrics.csv, gi.csv, summary.md, residency.png, bytes.png, "
      "frames/)\n%s%s",
      out.c_str(), summaryMarkdown(summary).c_str(), giMd.c_str());
  return failed.empty() ? 0 : 1;
}

}  // namespace sdfstream::cli
