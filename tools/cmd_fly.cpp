// sdfstream fly: drives a camera along a path over a world pack, streaming its tiles into the
// cascade stack without ever waiting on disk, renders frames, and writes streaming metrics.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "demo/fly_path.h"
#include "demo/frame_image.h"
#include "demo/plot.h"
#include "gi/camera.h"
#include "gi/gpu_stack_tracer.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/stream_metrics.h"
#include "tools/args.h"
#include "tools/commands.h"

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

}  // namespace

int runFly(int argc, char** argv) {
  Args args(argc, argv, 2,
            {"-o", "--path", "--speed", "--frames", "--width", "--height", "--image-every",
             "--cascades", "--atlas-mib", "--upload-mib", "--device", "--loader-threads"},
            {"--help", "-h", "--cpu", "--no-pacing"});
  if (args.has("--help") || args.has("-h")) {
    std::puts(
        "usage: sdfstream fly WORLD -o DIR [options]\n"
        "\n"
        "Flies a camera over a world pack (headless), streaming tiles into camera-centred\n"
        "cascades without waiting on disk. Writes DIR/frames/frame-NNNN.png, DIR/metrics.csv,\n"
        "DIR/summary.md, DIR/residency.png and DIR/bytes.png.\n"
        "\n"
        "  --path FILE        waypoints, one 'x y z' per line (default: a route across the world)\n"
        "  --speed M/S        camera speed (default 80 m/s, a fast fly-over)\n"
        "  --no-pacing        run frames back to back instead of at 30 per wall-clock second\n"
        "  --frames N         frames at 30 per second of path time (default 300)\n"
        "  --width W --height H   frame size (default 320 x 180)\n"
        "  --image-every K    write every K-th frame as PNG (default frames/6)\n"
        "  --cascades N       cascades (default 6, at most the pack's LOD count)\n"
        "  --atlas-mib N      shared brick atlas budget (default 96)\n"
        "  --upload-mib N     brick bytes uploaded per frame at most (default 16)\n"
        "  --loader-threads N tile loader threads (default 2)\n"
        "  --device NAME | --cpu   GPU choice, or trace with the CPU reference");
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

  StreamingOptions so;
  so.cascades = args.integer("--cascades", 6, 1, 8);
  const std::size_t slotBytes = 4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);
  so.atlasSlots = std::uint32_t(args.number("--atlas-mib", 96.0) * double(1 << 20) / slotBytes);
  so.uploadBytesPerFrame = std::size_t(args.number("--upload-mib", 16.0) * double(1 << 20));
  LoaderOptions lo;
  lo.threads = args.integer("--loader-threads", 2, 1, 64);
  TileLoader loader(store, lo);
  CascadeStack stack(store, loader, so);

  std::unique_ptr<gpu::Context> context = gpuContextFromArgs(args);
  std::unique_ptr<GpuStackTracer> tracer =
      context ? std::make_unique<GpuStackTracer>(*context, stack) : nullptr;
  fs::create_directories(out / "frames");
  std::printf("fly: %s, %d frames along %.0f m at %.1f m/s, %d cascades, atlas %.0f MiB, on %s\n",
              world.c_str(), frames, length, speed, stack.cascadeCount(),
              double(stack.atlasBytes()) / (1 << 20),
              context ? context->deviceName().c_str() : "CPU reference");

  std::vector<FrameMetrics> metrics;
  TraceSettings settings;
  // Frames are paced at 30 per wall-clock second (unless --no-pacing) so the loader threads get
  // the same real time per frame as they would in an interactive application.
  const auto start = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    double seconds = f / 30.0;
    if (!args.has("--no-pacing"))
      std::this_thread::sleep_until(start + std::chrono::microseconds(std::int64_t(seconds * 1e6)));
    double s = speed * seconds;
    Camera cam;
    cam.position = path.position(s);
    glm::dvec3 dir = path.direction(s);
    cam.target = cam.position + glm::normalize(dir + glm::dvec3(0.0, -0.25, 0.0)) * 10.0;
    cam.fovYDegrees = 60.0;

    FrameMetrics m;
    m.frame = f;
    m.seconds = seconds;
    m.camera = cam.position;
    auto t0 = std::chrono::steady_clock::now();
    m.stream = stack.update(cam.position, glm::normalize(cam.target - cam.position));
    m.updateMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::vector<std::uint32_t> dirty = stack.takeDirtySlots();
    if (tracer) tracer->sync(stack, dirty);
    m.gpuBytes = stack.atlasBytes() + std::size_t(stack.cascadeCount()) * layout::kCascadePageCount * 4;

    if (f % imageEvery == 0 || f == frames - 1) {
      CascadeStackImage img = stack.stackImage();
      auto rays = primaryRaysFrom(cam, width, height, img.toStack(cam.position));
      std::vector<gpu_shared::TraceHit> hits;
      if (tracer) {
        hits = tracer->trace(rays, settings);
        m.traceMilliseconds = tracer->lastMilliseconds("trace_stack");
      } else {
        hits = traceStackCpu(img, rays, settings);
      }
      char name[64];
      std::snprintf(name, sizeof name, "frame-%04d.png", f);
      writePng(out / "frames" / name, shadeHits(hits, width, height));
    }
    m.loader = loader.takeStats();
    metrics.push_back(std::move(m));
    if (f % std::max(1, frames / 10) == 0 || f == frames - 1)
      std::fprintf(stderr, "  frame %d/%d: %u missing pages, %zu tiles cached\n", f + 1, frames,
                   metrics.back().stream.missingPages, metrics.back().loader.cachedTiles);
  }

  writeMetricsCsv(out / "metrics.csv", metrics);
  MetricsSummary summary = summarize(metrics);
  std::string md = "# Fly-through summary\n\nWorld: " + world.string() + "\n\n" +
                   summaryMarkdown(summary);
  auto failed = loader.failedTiles();
  if (!failed.empty()) {
    md += "\nTiles that failed to load (reported, never treated as empty):\n";
    for (const TileKey& k : failed)
      md += "- tile " + std::to_string(k.coord.x) + "_" + std::to_string(k.coord.y) + "_" +
            std::to_string(k.coord.z) + " LOD " + std::to_string(k.lod) + "\n";
  }
  writeFileAtomically(out / "summary.md", md.data(), md.size());
  writePlots(out, metrics);
  std::printf("fly: wrote %s (metrics.csv, summary.md, residency.png, bytes.png, frames/)\n%s",
              out.c_str(), summaryMarkdown(summary).c_str());
  return failed.empty() ? 0 : 1;
}

}  // namespace sdfstream::cli
