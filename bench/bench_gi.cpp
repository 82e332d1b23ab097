#include "bench/bench_gi.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>

#include "bench/bench_gi_configs.h"
#include "bench/bench_gi_diagnose.h"
#include "bench/bench_gi_points.h"
#include "bench/bench_gi_report.h"
#include "bench/bench_gi_run.h"
#include "bench/bench_gi_scenes.h"
#include "bench/gpu_clock_warmup.h"
#include "core/stopwatch.h"
#include "demo/frame_image.h"
#include "gi/probe_field_frame.h"
#include "reference/irradiance_cache.h"
#include "reference/metrics.h"

namespace sdfstream::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The scene's configurations: the sweep (or the GPU table's), filtered by --configs.
std::vector<GiConfig> configsToRun(const BenchScene& scene, const GiBenchOptions& opt) {
  std::vector<GiConfig> run =
      opt.gpuTable ? gpuTableConfigs(scene) : sweepConfigs(scene, opt.quick);
  if (!opt.only.empty())
    std::erase_if(run, [&](const GiConfig& c) {
      return std::find(opt.only.begin(), opt.only.end(), c.name) == opt.only.end();
    });
  return run;
}

// The reference irradiance at every point (cached on disk), its own noise, and the noise floor
// of both metrics from a second reference of another seed; writes the reference images.
void computeReference(const BenchScene& scene, const reference::PathTracer& tracer,
                      const GiBenchOptions& opt, const fs::path& sceneDir, ViewPoints& points,
                      SceneReport& rep, Clock::time_point refStart) {
  reference::CacheOutcome outcome;
  const auto est =
      reference::cachedIrradiance(opt.out / "reference", tracer, points.position, points.normal,
                                  opt.samples, reference::IrradianceKind::NoDirectLights, &outcome);
  double noise = 0.0;
  for (const auto& x : est) {
    points.reference.push_back(x.mean);
    double e = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double s = double(x.halfWidth95[c]) / 1.96;
      e += s * s / (double(x.mean[c]) * double(x.mean[c]) + 1e-2);
    }
    noise += e / 3.0;
  }
  rep.referenceNoise = est.empty() ? 0.0 : noise / double(est.size());
  rep.referenceCache =
      outcome == reference::CacheOutcome::Loaded ? "loaded from cache" : "computed";
  rep.referenceSamples = opt.samples;
  rep.referenceSeconds = secondsSince(refStart);
  std::printf("  reference: %zu points x %u paths (%s, %.1f s); its own noise, as relMSE: %.2e\n",
              points.position.size(), opt.samples, rep.referenceCache.c_str(), rep.referenceSeconds,
              rep.referenceNoise);
  // A second, independent reference (another seed, same samples): how far two references
  // differ is the floor below which differences between configurations are noise.
  reference::PathTracerSettings other;
  other.seed = 2;
  reference::PathTracer tracer2(*scene.triangles, scene.lights, other);
  const auto est2 =
      reference::cachedIrradiance(opt.out / "reference", tracer2, points.position, points.normal,
                                  opt.samples, reference::IrradianceKind::NoDirectLights);
  std::vector<glm::vec3> second;
  for (const auto& x : est2) second.push_back(x.mean);
  rep.floorRelMSE = reference::relMSE(second, points.reference);
  if (opt.diagnose) {
    reference::PathTracerSettings oneBounce;
    oneBounce.maxDepth = 1;
    reference::PathTracer tracer1(*scene.triangles, scene.lights, oneBounce);
    for (const auto& x :
         reference::cachedIrradiance(opt.out / "reference", tracer1, points.position, points.normal,
                                     opt.samples, reference::IrradianceKind::NoDirectLights))
      points.referenceOneBounce.push_back(x.mean);
  }
  for (std::size_t k = 0; k < points.views(); ++k) {
    const auto img = shadedImage(points, k, points.reference);
    double sum = 0.0;
    for (const glm::vec3& c : img) sum += luminance(c);
    const double mean =
        sum / double(std::max<std::size_t>(1, points.start[k + 1] - points.start[k]));
    points.exposure.push_back(mean > 0.0 ? float(0.18 / mean) : 1.0f);
    writeToneMappedPng(sceneDir / (points.names[k] + "-reference.png"), img, points.width,
                       points.height, points.exposure.back());
    rep.floorFlip += reference::flip(reference::toneMapAces(img, points.exposure.back()),
                                     reference::toneMapAces(shadedImage(points, k, second),
                                                            points.exposure.back()),
                                     points.width, points.height)
                         .mean /
                     double(points.views());
  }
  std::printf("  two independent references differ by relMSE %.4f, FLIP %.4f (noise floor)\n",
              rep.floorRelMSE, rep.floorFlip);
}

// The points to compare at: on the source triangles (with the reference there, unless only the
// GPU table is made), or for the large world from our own SDF.
ViewPoints comparisonPoints(gpu::Context& ctx, const BenchScene& scene, const GiBenchOptions& opt,
                            const std::map<int, StreamedStack>& stacks, const fs::path& sceneDir,
                            SceneReport& rep) {
  if (!scene.triangles) {
    const StreamedStack& st = stacks.begin()->second;
    return sdfVisiblePoints(ctx, scene, *st.stack, st.allSlots, opt.width, opt.height);
  }
  const auto refStart = Clock::now();
  reference::PathTracer tracer(*scene.triangles, scene.lights);
  EmbreeScene embree(*scene.triangles);
  ViewPoints points = visiblePoints(scene, tracer, embree, opt.width, opt.height);
  if (!opt.gpuTable) computeReference(scene, tracer, opt, sceneDir, points, rep, refStart);
  return points;
}

// One probe query per point, and at most 1024 of them for the convergence test.
void addQueries(SceneContext& sc, const CascadeStackImage& img, double voxelSize) {
  const ViewPoints& points = sc.points;
  for (std::size_t i = 0; i < points.position.size(); ++i) {
    std::size_t k = 0;
    while (points.start[k + 1] <= i) ++k;
    const glm::vec3 toCamera = glm::normalize(points.cameras[k].position - points.position[i]);
    // Half a LOD-0 voxel off the triangle, towards the viewer: where the SDF's own surface
    // is for open sheets (mesh_to_sdf.h: unsigned distance minus half a voxel), i.e. where the
    // GI's renderer would shade; the true irradiance barely changes over that distance.
    const glm::dvec3 at = glm::dvec3(points.position[i]) +
                          glm::dvec3(points.normal[i]) * (sc.opt.queryOffsetVoxels * voxelSize);
    gpu_shared::ProbeQuery q{glm::vec4(img.toStack(at), 0.0f), glm::vec4(points.normal[i], 0.0f),
                             glm::vec4(toCamera, 0.0f)};
    sc.queries.push_back(q);
  }
  // The sampling pass's order: per view, 8×8 tiles row by row, each in Z-order (bits of x and y
  // interleaved), so 4 consecutive queries are a 2×2 quad, 8 a 4×2 block (a sharing group of
  // probe_sample.comp) and a 32-query warp an 8×4 block.
  const int width = std::max(points.width, 1);
  auto tileKey = [&](std::size_t i) {
    const int x = points.pixel[i] % width, y = points.pixel[i] / width;
    std::uint32_t z = 0;
    for (int b = 0; b < 3; ++b)
      z |= std::uint32_t(((x >> b) & 1) << (2 * b)) | std::uint32_t(((y >> b) & 1) << (2 * b + 1));
    return std::uint64_t(y / 8) << 40 | std::uint64_t(x / 8) << 8 | z;
  };
  sc.sampleOrder.resize(points.position.size());
  for (std::size_t i = 0; i < sc.sampleOrder.size(); ++i) sc.sampleOrder[i] = std::uint32_t(i);
  for (std::size_t k = 0; k < points.views(); ++k)
    std::stable_sort(sc.sampleOrder.begin() + std::ptrdiff_t(points.start[k]),
                     sc.sampleOrder.begin() + std::ptrdiff_t(points.start[k + 1]),
                     [&](std::uint32_t a, std::uint32_t b) { return tileKey(a) < tileKey(b); });
  sc.sampleQueries.clear();
  for (std::uint32_t i : sc.sampleOrder) sc.sampleQueries.push_back(sc.queries[i]);
  const std::size_t pixels = std::size_t(width) * std::size_t(std::max(points.height, 1));
  sc.imageQueries.assign(points.views() * pixels, gpu_shared::ProbeQuery{});
  for (std::size_t k = 0; k < points.views(); ++k)
    for (std::size_t i = points.start[k]; i < points.start[k + 1]; ++i)
      sc.imageQueries[k * pixels + std::size_t(points.pixel[i])] = sc.queries[i];
  const std::size_t stride = std::max<std::size_t>(1, points.position.size() / 1024);
  for (std::size_t i = 0; i < points.position.size(); i += stride) {
    sc.testQueries.push_back(sc.queries[i]);
    sc.testIndex.push_back(i);
  }
}

// The receivers in five groups by their reference one-bounce luminance (darkest first): each
// group's share of the one-bounce light, and GI/reference for one bounce and for everything. A
// loss concentrated in the brightest group points at a few receivers (a window's sill, a sunlit
// patch's neighbours); one spread evenly, at the sampling everywhere.
std::string bounceQuintiles(std::span<const glm::vec3> gi1, std::span<const glm::vec3> ref1,
                            std::span<const glm::vec3> giAll, std::span<const glm::vec3> refAll) {
  std::vector<std::size_t> order(ref1.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return luminance(ref1[a]) < luminance(ref1[b]); });
  double total1 = 0;
  for (const glm::vec3& r : ref1) total1 += luminance(r);
  std::string s =
      "\nThe receivers by their reference one-bounce light, in fifths (darkest first):\n\n| fifth "
      "| share of the one-bounce light | one bounce GI/ref | everything GI/ref |\n"
      "|---|---|---|---|\n";
  for (int q = 0; q < 5; ++q) {
    double g1 = 0, r1 = 0, ga = 0, ra = 0;
    for (std::size_t j = order.size() * q / 5; j < order.size() * (q + 1) / 5; ++j) {
      const std::size_t i = order[j];
      g1 += luminance(gi1[i]);
      r1 += luminance(ref1[i]);
      ga += luminance(giAll[i]);
      ra += luminance(refAll[i]);
    }
    char row[160];
    std::snprintf(row, sizeof row, "| %d | %.1f%% | %.3f | %.3f |\n", q + 1,
                  total1 > 0 ? 100.0 * r1 / total1 : 0.0, r1 > 0 ? g1 / r1 : 0.0,
                  ra > 0 ? ga / ra : 0.0);
    s += row;
    std::printf("    diagnose: one-bounce fifth %d: share %.1f%%, GI/ref %.3f, everything %.3f\n",
                q + 1, total1 > 0 ? 100.0 * r1 / total1 : 0.0, r1 > 0 ? g1 / r1 : 0.0,
                ra > 0 ? ga / ra : 0.0);
  }
  return s;
}

// --diagnose: the default without its multi-bounce feedback (probe-ray hits shaded with their
// direct light and emission only) against the reference capped at one surface hit -- the same
// transport -- and what the bounces beyond add in both.
void diagnoseBounces(SceneContext& sc, const GiConfig& def, const std::vector<glm::vec3>& eFull,
                     const fs::path& sceneDir, SceneReport& rep) {
  GiConfig one = def;
  one.name = def.name + "-one-bounce";
  one.probes.bounceGain = 0.0f;
  one.converge = false;
  std::vector<glm::vec3> e1;
  RunReports into;
  into.rayRadiance = &rep;
  runConfig(sc, one, &e1, into);
  const ViewPoints& p = sc.points;
  double gi1 = 0, giAll = 0, ref1 = 0, refAll = 0;
  for (std::size_t i = 0; i < e1.size(); ++i) {
    gi1 += luminance(e1[i]);
    giAll += luminance(eFull[i]);
    ref1 += luminance(p.referenceOneBounce[i]);
    refAll += luminance(p.reference[i]);
  }
  char s[640];
  std::snprintf(
      s, sizeof s,
      "\nBounces (mean luminance over the points): one bounce -- sky and emission seen, plus "
      "the direct light at the first hit -- GI %.4g vs reference %.4g (ratio %.3f, relMSE "
      "%.4f); the bounces beyond it GI %.4g vs reference %.4g (ratio %.3f); everything GI %.4g "
      "vs %.4g (ratio %.3f).\n",
      gi1, ref1, ref1 > 0 ? gi1 / ref1 : 0.0, reference::relMSE(e1, p.referenceOneBounce),
      giAll - gi1, refAll - ref1, refAll - ref1 > 0 ? (giAll - gi1) / (refAll - ref1) : 0.0, giAll,
      refAll, refAll > 0 ? giAll / refAll : 0.0);
  std::printf("    diagnose:%s", s + 1);
  rep.diagnosis += s;
  rep.diagnosis += bounceQuintiles(e1, p.referenceOneBounce, eFull, p.reference);
  for (std::size_t view = 0; view < p.views(); ++view) {
    writeToneMappedPng(sceneDir / (p.names[view] + "-" + one.name + ".png"),
                       shadedImage(p, view, e1), p.width, p.height, p.exposure[view]);
    writeToneMappedPng(sceneDir / (p.names[view] + "-reference-one-bounce.png"),
                       shadedImage(p, view, p.referenceOneBounce), p.width, p.height,
                       p.exposure[view]);
  }

  // E/E_ref by the cascade each receiver is sampled from (the finest whose probe grid holds it
  // half a spacing inside, as probeFieldIrradiance picks it).
  const CascadeStackImage img = sc.stacks.at(def.cascades).stack->stackImage();
  probe::ProbeFrameInputs in;
  in.cameraWorld = sc.scene.streamCamera;
  in.viewDirection = sc.scene.viewDirection;
  probe::ProbeFieldFrameBuilder builder(def.probes);
  const probe::ProbeFieldFrame f = builder.build(img, in, 0);
  const std::size_t cascades = f.volumes.size();
  const std::vector<std::uint32_t> picks = samplingCascades(f.volumes, sc.queries);
  std::vector<double> gi(cascades, 0.0), ref(cascades, 0.0);
  std::vector<std::size_t> count(cascades, 0);
  for (std::size_t i = 0; i < sc.queries.size(); ++i) {
    const std::uint32_t pick = picks[i];
    gi[pick] += luminance(eFull[i]);
    ref[pick] += luminance(p.reference[i]);
    ++count[pick];
  }
  rep.diagnosis +=
      "\nReceivers by the cascade they are sampled from (the finest whose probe grid holds "
      "them half a spacing inside), mean luminance:\n\n| cascade | receivers | GI | reference | "
      "E/E_ref |\n|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < cascades; ++c) {
    if (count[c] == 0) continue;
    char row[160];
    std::snprintf(row, sizeof row, "| %zu | %zu | %.4g | %.4g | %.3f |\n", c, count[c],
                  gi[c] / double(count[c]), ref[c] / double(count[c]),
                  ref[c] > 0.0 ? gi[c] / ref[c] : 0.0);
    rep.diagnosis += row;
    std::printf("    diagnose: receivers sampled from cascade %zu: %zu, E/E_ref %.3f\n", c,
                count[c], ref[c] > 0.0 ? gi[c] / ref[c] : 0.0);
  }
}

// Every configuration in turn; the default and plain DDGI also get images per view.
void runConfigs(SceneContext& sc, const std::vector<GiConfig>& run, const fs::path& sceneDir,
                SceneReport& rep) {
  const ViewPoints& points = sc.points;
  const int rounds = sc.opt.gpuTable ? std::max(1, sc.opt.rounds) : 1;
  rep.rounds = rounds;
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t k = 0; k < run.size(); ++k) {
      const GiConfig& c = run[k];
      std::vector<glm::vec3> e;
      const bool isDefault = c.name == "default", isBaseline = c.name == "plain-ddgi";
      // The peers run on the default's rays; the diagnosis on --diagnose-config's (the default).
      const bool diagnosed = sc.opt.diagnose && c.name == sc.opt.diagnoseConfig;
      RunReports into;
      if (!sc.opt.gpuTable) {
        into.peers = isDefault && sc.opt.peers ? &rep : nullptr;
        into.diagnosis = diagnosed ? &rep : nullptr;
      }
      ConfigResult r = runConfig(sc, c, &e, into);
      std::printf(
          "    %-22s update %8.2f ms  sample %7.2f ms  relMSE %8.4f  FLIP %.4f  E/Eref %.3f  "
          "flat spread %.3f (ref %.3f)  converge %3d  %6.1f MiB  (%.0f s)\n",
          c.name.c_str(), r.updateMs, r.sampleMs, r.relMSE, r.flip, r.energyRatio, r.flatSpread,
          r.flatSpreadReference, r.framesToConverge, r.memoryMiB(), r.wallSeconds);
      std::fflush(stdout);
      if ((isDefault || isBaseline) && !points.reference.empty())
        for (std::size_t view = 0; view < points.views(); ++view)
          writeToneMappedPng(sceneDir / (points.names[view] + "-" + c.name + ".png"),
                             shadedImage(points, view, e), points.width, points.height,
                             points.exposure[view]);
      if (diagnosed && !points.referenceOneBounce.empty()) diagnoseBounces(sc, c, e, sceneDir, rep);
      if (round == 0)
        rep.configs.push_back(std::move(r));
      else if (r.updateMs + r.sampleMs < rep.configs[k].updateMs + rep.configs[k].sampleMs)
        rep.configs[k] = std::move(r);
    }
  }
}

SceneReport runScene(gpu::Context& ctx, const GiBenchOptions& opt, const std::string& name) {
  const auto start = Clock::now();
  SceneReport rep;
  rep.name = name;
  std::string skip;
  std::optional<BenchScene> scene = loadBenchScene(name, opt.data, opt.largeWorld, &skip);
  if (!scene) {
    std::printf("  %s\n", skip.c_str());
    rep.skipped = skip;
    return rep;
  }
  if (opt.gpuTable && scene->views.size() > 1) {  // the table samples one full-HD view
    scene->views.resize(1);
    scene->viewNames.resize(1);
  }
  rep.description = scene->description;
  rep.voxelSize = scene->voxelSize;
  rep.lods = scene->lods;
  rep.warmupFrames = opt.warmup;
  rep.measuredFrames = opt.measured;
  const fs::path sceneDir = opt.out / name;
  fs::create_directories(sceneDir);

  const fs::path pack = benchScenePack(*scene, opt.out / "packs", &rep.importSeconds);
  std::printf("  pack %s (%s)\n", pack.c_str(),
              rep.importSeconds > 0
                  ? ("imported in " + std::to_string(rep.importSeconds) + " s").c_str()
                  : "cached");
  PackTileStore store(pack);
  TileLoader loader(store);
  std::map<int, StreamedStack> stacks;
  const std::vector<GiConfig> run = configsToRun(*scene, opt);
  for (const GiConfig& c : run)
    if (!stacks.count(c.cascades))
      stacks.emplace(c.cascades, streamStack(store, loader, *scene, c.cascades));

  ViewPoints points = comparisonPoints(ctx, *scene, opt, stacks, sceneDir, rep);
  rep.points = points.position.size();
  rep.views = int(points.views());
  rep.width = opt.width;
  rep.height = opt.height;

  if (opt.gpuTable) {  // the stack of the default's cascades
    const auto it = stacks.find(scene->defaultCascades);
    const StreamedStack& st = it != stacks.end() ? it->second : stacks.rbegin()->second;
    rep.primary = primaryTraceTiming(ctx, *scene, *st.stack, st.allSlots, opt.width, opt.height);
    const PrimaryTraceTiming& p = rep.primary;
    std::printf(
        "  primary rays: %zu, %.3f ms (%.3f-%.3f; %.3f cold, warm-up %.1f s%s), %.1f steps a ray "
        "(surface %.1f, band %.1f, clamped %.1f, empty pages %.1f, missing %.1f; CPU steps %s)\n",
        p.rays, p.milliseconds, p.minMilliseconds, p.maxMilliseconds, p.coldMilliseconds,
        p.warmupSeconds, p.settled ? "" : ", not settled", p.meanSteps, p.stepsByKind[0],
        p.stepsByKind[1], p.stepsByKind[2], p.stepsByKind[3], p.stepsByKind[4],
        p.cpuStepsEqual ? "equal" : "differ");
  }

  SceneContext sc{ctx, opt, *scene, stacks, points, {}, {}, {}, {}, {}, {}};
  std::unique_ptr<GpuStackTracer> warmTracer;
  std::unique_ptr<GpuClockWarmup> warmup;
  if (opt.gpuTable) {  // the primary rays again, as the work that brings the clocks up
    const StreamedStack& st = stacks.rbegin()->second;
    warmTracer = std::make_unique<GpuStackTracer>(ctx, *st.stack);
    warmTracer->sync(*st.stack, st.allSlots);
    warmup = std::make_unique<GpuClockWarmup>(
        *warmTracer, streamCameraRays(*scene, *st.stack, opt.width, opt.height));
    sc.warmGpu = [&warmup] {
      const GpuClockWarmup::Result w = warmup->run(1.0);
      std::printf("    GPU warm-up: %d batches, %.1f s, a dispatch %.3f -> %.3f ms%s\n", w.batches,
                  w.seconds, w.firstMs, w.lastMs, w.settled ? "" : " (not settled)");
    };
  }
  addQueries(sc, stacks.begin()->second.stack->stackImage(), scene->voxelSize);
  runConfigs(sc, run, sceneDir, rep);
  rep.seconds = secondsSince(start);
  return rep;
}

}  // namespace

void applyGiBenchModeDefaults(GiBenchOptions& opt) {
  if (opt.quick) {
    opt.width = 96;
    opt.height = 72;
    opt.samples = 256;
    opt.warmup = 8;  // Cornell, spacing 2: relMSE at frame 8 is within 5% of frame 40's
    opt.measured = 4;
    opt.offFrames = 3;
    opt.convergeCap = 16;
  }
  if (opt.gpuTable) {
    opt.width = 1920;
    opt.height = 1080;
    opt.warmup = 16;
    opt.measured = 8;
    opt.convergeCap = 0;
    // A Sponza probe gets an update every ~2.2 frames while its vigilance lasts (32 updates at
    // 8,192 probes a list), and one quiet rotation cycle more puts it to sleep.
    opt.settledFrames = 160;
  }
}

std::vector<std::string> defaultGiBenchScenes(const GiBenchOptions& opt) {
  if (opt.quick)
    return {"cornell-box", fs::exists(opt.data / "breakfast-room") ? "breakfast-room" : "bunny"};
  if (opt.gpuTable) return {"sponza"};
  return {"cornell-box", "sponza", "breakfast-room", "courtyard", "emissive-room", "large-world"};
}

int runGiBench(const GiBenchOptions& opt) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines reach a pipe as they happen
  const auto start = Clock::now();
  std::unique_ptr<gpu::Context> context = gpu::Context::create(opt.device);
  RunInfo info;
  info.device = context->deviceName();
  info.mode = opt.gpuTable ? "gpu-table" : opt.quick ? "quick" : "full";
  info.command = opt.command;
  std::printf("bench gi (%s) on %s -> %s\n", info.mode.c_str(), info.device.c_str(),
              opt.out.c_str());
  fs::create_directories(opt.out);

  std::vector<SceneReport> reports;
  for (const std::string& name : opt.scenes) reports.push_back(runScene(*context, opt, name));
  info.seconds = secondsSince(start);
  if (opt.gpuTable) {
    for (const SceneReport& r : reports)
      if (r.skipped.empty()) writeGpuTable(opt.out, r, info);
  } else {
    writeBenchGiOutputs(opt.out, reports, info);
  }
  std::printf("bench gi: %.0f s; wrote %s\n", info.seconds, opt.out.c_str());
  return 0;
}

}  // namespace sdfstream::bench
