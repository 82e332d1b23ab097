// sdfstream bench gi (issue 6 items 3-6): run time vs error of the probe GI against a path-traced
// reference, over a sweep of the probe settings, with plain DDGI built from the same code as the
// baseline, and the probe-ray traversal against its peers on one frame's rays. See --help.
//
// Per scene: source triangles -> world pack (cached under OUT/packs) -> cascade stacks settled
// around the scene's player position (one per cascade count) -> the reference irradiance at the
// visible points of the scene's views (PathTracer, NoDirectLights, cached under OUT/reference) ->
// per configuration a fresh GiSystem: warm-up frames, measured frames (GPU pass times, medians),
// irradiance at every visible point (relMSE, FLIP of albedo/π·E images), the light switched off
// and on again (frames until within 5% of the converged field), device memory.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/error.h"
#include "demo/frame_image.h"
#include "gi/camera.h"
#include "gi/gi_system.h"
#include "gi/gpu_stack_tracer.h"
#include "gi/probe_math.h"
#include "gpu/context.h"
#include "reference/irradiance_cache.h"
#include "reference/metrics.h"
#include "tools/args.h"
#include "tools/bench_gi_peers.h"
#include "tools/bench_gi_report.h"
#include "tools/bench_gi_scenes.h"
#include "tools/commands.h"

namespace sdfstream::cli {
namespace {

namespace fs = std::filesystem;
using namespace gi_bench;
using Clock = std::chrono::steady_clock;
using probe::ProbeFieldSettings;

double secondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

struct Options {
  bool quick = false, gpuTable = false, peers = true, verbose = false;
  std::vector<std::string> only;  // --configs: run just these configurations
  fs::path out = "out/bench-gi", data = "../shared/data", largeWorld = "out/worlds/large-4km";
  std::vector<std::string> scenes;
  int width = 160, height = 120;
  std::uint32_t samples = 512;
  int warmup = 32, measured = 6, offFrames = 8, convergeCap = 32;
  double queryOffsetVoxels = 0.5;
};

struct GiConfig {
  std::string name, family, change;
  ProbeFieldSettings probes;
  int cascades = 1;
  bool converge = true;  // measure frames to converge after a light switch
  std::string base;      // the configuration `change` is relative to ("" = none)
};

const char* visibilityName(ProbeFieldSettings::Visibility v) {
  switch (v) {
    case ProbeFieldSettings::Visibility::Chebyshev:
      return "chebyshev";
    case ProbeFieldSettings::Visibility::Sdf:
      return "sdf";
    case ProbeFieldSettings::Visibility::ChebyshevAndSdf:
      return "chebyshev+sdf";
  }
  return "?";
}

// "Plain DDGI" (issue 6 item 4) from the same code: a uniform grid of one probe per brick, no
// relocation, no states, no hit cache, Chebyshev visibility only.
ProbeFieldSettings plainDdgi() {
  ProbeFieldSettings s;
  s.spacingBricks = 1;
  s.relocation = false;
  s.states = false;
  s.hitCache = false;
  s.visibility = ProbeFieldSettings::Visibility::Chebyshev;
  return s;
}

// The sweep: our default; the switches (hit cache, states, relocation, visibility) each changed
// alone from an ablation base; rays, spacing and cascade count changed alone from the default;
// the baseline and the baseline at other ray counts (so plain DDGI is a curve, not one point).
// Full mode: the ablation base is the default and every configuration measures convergence.
// Quick mode (lavapipe on 2 cores: a 17³ x 128-ray frame costs seconds there): the ablation base
// is spacing 2 (9³ probes per cascade, ~6x cheaper), no extra cascade counts, rays 32 only, and
// only the base measures convergence.
std::vector<GiConfig> sweepConfigs(const BenchScene& scene, bool quick) {
  std::vector<GiConfig> out;
  const int cascades = scene.defaultCascades;
  auto add = [&](std::string name, std::string family, std::string change, ProbeFieldSettings s,
                 int c, bool converge) {
    const std::string base = change.empty()           ? ""
                             : family == "plain-ddgi" ? "plain-ddgi"
                                                      : "default";
    out.push_back({std::move(name), std::move(family), std::move(change), s, c, converge, base});
  };
  const ProbeFieldSettings def;
  add("default", "ours", "", def, cascades, !quick);
  add("plain-ddgi", "plain-ddgi", "", plainDdgi(), cascades, !quick);
  const std::vector<std::uint32_t> rays =
      quick ? std::vector<std::uint32_t>{32} : std::vector<std::uint32_t>{32, 64, 256};
  for (std::uint32_t r : rays) {
    ProbeFieldSettings s = def;
    s.raysPerProbe = r;
    add("rays-" + std::to_string(r), "ours", "rays " + std::to_string(r), s, cascades, !quick);
  }
  for (std::uint32_t sp : {2u, 4u}) {
    ProbeFieldSettings s = def;
    s.spacingBricks = sp;
    add("spacing-" + std::to_string(sp), "ours", "spacing " + std::to_string(sp) + " bricks", s,
        cascades, !quick || sp == 2);
  }
  if (!quick)
    for (int c : scene.cascadeSweep)
      if (c != cascades)
        add("cascades-" + std::to_string(c), "ours", std::to_string(c) + " cascades", def, c, true);
  {
    ProbeFieldSettings base = def;
    std::string prefix;
    if (quick) {
      base.spacingBricks = 2;
      prefix = "spacing-2-";
    }
    ProbeFieldSettings s = base;
    s.hitCache = false;
    add(prefix + "no-hit-cache", "ours", "hit cache off", s, cascades, !quick);
    s = base;
    s.states = false;
    add(prefix + "no-states", "ours", "states off", s, cascades, !quick);
    s = base;
    s.relocation = false;
    add(prefix + "no-relocation", "ours", "relocation off", s, cascades, !quick);
    s = base;
    s.visibility = ProbeFieldSettings::Visibility::Chebyshev;
    add(prefix + "vis-chebyshev", "ours", "visibility chebyshev", s, cascades, !quick);
    s.visibility = ProbeFieldSettings::Visibility::Sdf;
    add(prefix + "vis-sdf", "ours", "visibility sdf", s, cascades, !quick);
    if (quick)
      for (GiConfig& c : out)
        if (c.name.starts_with(prefix) && c.name != "spacing-2") c.base = "spacing-2";
  }
  if (!quick) {
    ProbeFieldSettings s = def;
    s.spacingBricks = 2;
    s.raysPerProbe = 64;
    add("spacing-2-rays-64", "ours", "spacing 2, rays 64", s, cascades, true);
    s.raysPerProbe = 256;
    add("spacing-2-rays-256", "ours", "spacing 2, rays 256", s, cascades, true);
  }
  for (std::uint32_t r : rays) {
    ProbeFieldSettings s = plainDdgi();
    s.raysPerProbe = r;
    add("plain-ddgi-rays-" + std::to_string(r), "plain-ddgi", "rays " + std::to_string(r), s,
        cascades, !quick);
  }
  return out;
}

// The visible surface points of every view: where the reference and the GI are compared.
struct ViewPoints {
  int width = 0, height = 0;
  std::vector<reference::PinholeCamera> cameras;
  std::vector<std::string> names;
  std::vector<glm::vec3> position, normal, albedo;  // world metres; linear albedo in [0, 1]
  std::vector<int> pixel;                           // index in its view's image
  std::vector<std::size_t> start;                   // first point of each view; + end
  std::vector<glm::vec3> reference;                 // E_ref (NoDirectLights); empty: none
  std::vector<float> exposure;                      // per view, for the tone map
};

ViewPoints visiblePoints(const BenchScene& scene, const reference::PathTracer& tracer,
                         const EmbreeScene& embree, int width, int height) {
  ViewPoints v;
  v.width = width;
  v.height = height;
  v.cameras = scene.views;
  v.names = scene.viewNames;
  for (const auto& cam : scene.views) {
    v.start.push_back(v.position.size());
    const auto pts = tracer.visiblePoints(cam, width, height);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (!pts[i].hit) continue;
      // The albedo where the camera ray lands (same triangle the path tracer found).
      const glm::vec3 d = glm::normalize(pts[i].position - cam.position);
      const auto hit = embree.intersect(cam.position, d, 0.0f, 1e30f);
      glm::vec3 a(0.0f);
      if (hit)
        a = glm::clamp(glm::vec3(sampleAlbedo(*scene.triangles, hit->triangle, hit->bary)), 0.0f,
                       1.0f);
      v.position.push_back(pts[i].position);
      v.normal.push_back(pts[i].normal);
      v.albedo.push_back(a);
      v.pixel.push_back(int(i));
    }
  }
  v.start.push_back(v.position.size());
  return v;
}

// The large world has no triangles: its visible points come from our own SDF (timing only).
ViewPoints sdfVisiblePoints(gpu::Context& ctx, const BenchScene& scene, const CascadeStack& stack,
                            std::span<const std::uint32_t> slots, int width, int height) {
  ViewPoints v;
  v.width = width;
  v.height = height;
  v.names = {"player"};
  GpuStackTracer tracer(ctx, stack);
  tracer.sync(stack, slots);
  const CascadeStackImage img = stack.stackImage();
  Camera cam;
  cam.position = scene.streamCamera;
  cam.target = scene.streamCamera + glm::dvec3(scene.viewDirection);
  cam.fovYDegrees = 60.0;
  const auto rays = primaryRaysFrom(cam, width, height, img.toStack(cam.position));
  const auto hits = tracer.trace(rays, TraceSettings{});
  v.start.push_back(0);
  for (std::size_t i = 0; i < hits.size(); ++i) {
    if (!(hits[i].flags & gpu_shared::kHitFlagHit)) continue;
    const glm::vec3 p =
        glm::vec3(rays[i].originTMin) + glm::vec3(rays[i].dirTMax) * hits[i].normalT.w;
    v.position.push_back(glm::vec3(img.cascade0MinWorld + glm::dvec3(p) * img.voxelSize0));
    v.normal.push_back(glm::normalize(glm::vec3(hits[i].normalT)));
    v.albedo.push_back(glm::vec3(0.5f));
    v.pixel.push_back(int(i));
  }
  v.start.push_back(v.position.size());
  reference::PinholeCamera pc;
  pc.position = glm::vec3(cam.position);
  pc.forward = scene.viewDirection;
  v.cameras.push_back(pc);
  return v;
}

float luminance(glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// albedo/π·E per pixel of view `k` (black where the view sees the sky).
std::vector<glm::vec3> shadedImage(const ViewPoints& v, std::size_t k,
                                   std::span<const glm::vec3> e) {
  std::vector<glm::vec3> img(std::size_t(v.width * v.height), glm::vec3(0.0f));
  for (std::size_t i = v.start[k]; i < v.start[k + 1]; ++i)
    img[std::size_t(v.pixel[i])] = v.albedo[i] / 3.14159265f * e[i];
  return img;
}

void writeToneMappedPng(const fs::path& path, const std::vector<glm::vec3>& radiance, int w, int h,
                        float exposure) {
  Image8 out;
  out.width = w;
  out.height = h;
  out.rgb.resize(std::size_t(w * h) * 3);
  for (std::size_t i = 0; i < radiance.size(); ++i) {
    const glm::vec3 s = reference::linearToSrgb(reference::toneMapAces(radiance[i], exposure));
    for (int c = 0; c < 3; ++c) out.rgb[i * 3 + c] = std::uint8_t(std::lround(255.0f * s[c]));
  }
  writePng(path, out);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct SceneContext {
  gpu::Context& ctx;
  const Options& opt;
  const BenchScene& scene;
  std::map<int, StreamedStack>& stacks;
  ViewPoints& points;
  std::vector<gpu_shared::ProbeQuery> queries, testQueries;
  std::vector<std::size_t> testIndex;  // testQueries[i] is point testIndex[i]
};

// Probe rays of one frame of `gi` (every probe that is not off, raysPerProbe rays each, this
// frame's rotation), in both frames, bounded by the coarsest cascade's window.
PeerRays probeRaySet(const GiSystem& gi, const CascadeStackImage& img, const ProbeFieldSettings& s,
                     const probe::ProbeFrameInputs& in, std::uint64_t frame) {
  probe::ProbeFieldFrameBuilder builder(s);
  const probe::ProbeFieldFrame f = builder.build(img, in, frame);
  const std::vector<glm::vec4> data = gi.probes().downloadProbeData();
  const std::uint32_t perVolume = s.probesPerVolume(), n = s.raysPerProbe;
  const gpu_shared::CascadeTraceParams& last = img.params.back();
  const glm::vec3 lo(last.offsetScale), hi = lo + glm::vec3(128.0f * last.offsetScale.w);
  PeerRays r;
  for (std::size_t c = 0; c < f.volumes.size(); ++c) {
    const gpu_shared::ProbeVolume& v = f.volumes[c];
    const glm::mat3 rot(glm::vec3(v.rayRotationCol0), glm::vec3(v.rayRotationCol1),
                        glm::vec3(v.rayRotationCol2));
    const glm::ivec3 counts(v.countsRays);
    for (std::uint32_t st = 0; st < perVolume; ++st) {
      const glm::vec4 d = data[c * perVolume + st];
      if (std::uint32_t(d.w) == gpu_shared::kProbeOff) continue;
      const glm::ivec3 storage(int(st % counts.x), int(st / counts.x % counts.y),
                               int(st / (counts.x * counts.y)));
      const glm::ivec3 logical = (storage - glm::ivec3(v.scroll) + counts) % counts;
      const glm::vec3 o =
          glm::vec3(v.originSpacing) + glm::vec3(logical) * v.originSpacing.w + glm::vec3(d);
      for (std::uint32_t i = 0; i < n; ++i) {
        const glm::vec3 dir = probe::rayDirection(i, n, rot);
        // Exit of the coarsest window (all peers get the same bound).
        float tExit = 1e30f;
        for (int a = 0; a < 3; ++a) {
          if (std::abs(dir[a]) < 1e-12f) continue;
          const float t = ((dir[a] > 0.0f ? hi[a] : lo[a]) - o[a]) / dir[a];
          tExit = std::min(tExit, std::max(t, 0.0f));
        }
        gpu_shared::TraceRay tr;
        tr.originTMin = glm::vec4(o, 0.0f);
        tr.dirTMax = glm::vec4(dir, tExit);
        r.stack.push_back(tr);
        r.origin.push_back(glm::vec3(img.cascade0MinWorld + glm::dvec3(o) * img.voxelSize0));
        r.direction.push_back(dir);
        r.tMax.push_back(float(double(tExit) * img.voxelSize0));
      }
    }
  }
  return r;
}

double bufferMiB(std::initializer_list<const gpu::Buffer*> buffers) {
  double bytes = 0.0;
  for (const gpu::Buffer* b : buffers) bytes += double(b->size());
  return bytes / double(1 << 20);
}

// One configuration, start to finish. `keep` receives the final irradiance at every point.
ConfigResult runConfig(SceneContext& sc, const GiConfig& cfg, std::vector<glm::vec3>* keep,
                       SceneReport* peersInto) {
  const auto start = Clock::now();
  const Options& opt = sc.opt;
  StreamedStack& st = sc.stacks.at(cfg.cascades);
  GiSettings gs;
  gs.probes = cfg.probes;
  GiSystem gi(sc.ctx, gs, std::uint32_t(cfg.cascades));
  probe::ProbeFrameInputs in;
  in.cameraWorld = sc.scene.streamCamera;
  in.viewDirection = sc.scene.viewDirection;
  SceneLights lights = sc.scene.lights;
  lights.version = 0;
  std::uint64_t frame = 0;
  auto step = [&] {
    const std::span<const std::uint32_t> dirty =
        frame == 0 ? std::span<const std::uint32_t>(st.allSlots) : std::span<const std::uint32_t>();
    return gi.update(*st.stack, dirty, lights, in, frame++);
  };

  ConfigResult r;
  r.config = cfg.name;
  r.family = cfg.family;
  r.change = cfg.change;
  r.base = cfg.base;
  r.rays = cfg.probes.raysPerProbe;
  r.spacing = cfg.probes.spacingBricks;
  r.cascades = std::uint32_t(cfg.cascades);
  r.hitCache = cfg.probes.hitCache;
  r.states = cfg.probes.states;
  r.relocation = cfg.probes.relocation;
  r.visibility = visibilityName(cfg.probes.visibility);
  r.probes = std::size_t(cfg.probes.probesPerVolume()) * std::size_t(cfg.cascades);

  GiFrameStats first = step();
  r.lightRelightMs = first.lightMilliseconds;
  for (int i = 1; i < opt.warmup; ++i) step();

  std::map<std::string, std::vector<double>> passes;
  std::vector<double> update, sample, probesUpdated, raysTraced, raysCached, steps;
  std::vector<glm::vec3> e;
  for (int m = 0; m < opt.measured; ++m) {
    const GiFrameStats s = step();
    double total = 0.0;
    for (const auto& t : gi.probes().lastTimings()) {
      passes[t.name].push_back(t.milliseconds);
      total += t.milliseconds;
      if (opt.verbose)
        std::printf("      frame %llu %s %.2f ms\n", (unsigned long long)frame - 1, t.name.c_str(),
                    t.milliseconds);
    }
    if (opt.verbose)
      std::printf("      frame %llu: %u probes, %u rays traced, %u cached, %llu steps\n",
                  (unsigned long long)frame - 1, s.probes.probesUpdated, s.probes.raysTraced,
                  s.probes.raysCached, (unsigned long long)s.probes.steps);
    update.push_back(total);
    probesUpdated.push_back(s.probes.probesUpdated);
    raysTraced.push_back(s.probes.raysTraced);
    raysCached.push_back(s.probes.raysCached);
    steps.push_back(double(s.probes.steps));
    e = gi.irradiance(sc.queries);
    sample.push_back(gi.lastSampleMilliseconds());
    if (opt.verbose && !sc.points.reference.empty())
      std::printf("      frame %llu: relMSE %.4f\n", (unsigned long long)frame - 1,
                  reference::relMSE(e, sc.points.reference));
  }
  for (auto& [name, v] : passes) r.passMs[name] = median(v);
  const double views = double(std::max<std::size_t>(1, sc.points.start.size() - 1));
  r.updateMs = median(update);
  r.sampleMs = median(sample) / views;
  r.frameMs = r.updateMs + r.sampleMs;
  // Best of the measured frames too: on a shared CPU (lavapipe) other processes inflate single
  // frames; the best is what the work itself costs, and where the two orders of two
  // configurations disagree, their difference is within the machine's noise.
  r.frameBestMs = *std::min_element(update.begin(), update.end()) +
                  *std::min_element(sample.begin(), sample.end()) / views;
  r.frameWorstMs = *std::max_element(update.begin(), update.end()) +
                   *std::max_element(sample.begin(), sample.end()) / views;
  r.sampleNsPerQuery = sc.queries.empty() ? 0.0 : median(sample) * 1e6 / double(sc.queries.size());
  r.probesUpdated = median(probesUpdated);
  r.raysTraced = median(raysTraced);
  r.raysCached = median(raysCached);
  r.steps = median(steps);
  r.probeMiB = double(gi.probes().deviceBytes()) / double(1 << 20);
  r.lightMiB = bufferMiB({&gi.lightCache().radianceBuffer()});
  const GpuStackScene& g = gi.scene();
  r.atlasMiB = bufferMiB({&g.pageTables(), &g.distance(), &g.albedo(), &g.emission(), &g.params()});

  if (!sc.points.reference.empty()) {
    r.relMSE = reference::relMSE(e, sc.points.reference);
    double sumGi = 0.0, sumRef = 0.0;
    for (std::size_t i = 0; i < e.size(); ++i) {
      sumGi += luminance(e[i]);
      sumRef += luminance(sc.points.reference[i]);
    }
    r.energyRatio = sumRef > 0.0 ? sumGi / sumRef : 0.0;
    double flipSum = 0.0;
    for (std::size_t k = 0; k + 1 < sc.points.start.size(); ++k) {
      const auto ref = reference::toneMapAces(shadedImage(sc.points, k, sc.points.reference),
                                              sc.points.exposure[k]);
      const auto test = reference::toneMapAces(shadedImage(sc.points, k, e), sc.points.exposure[k]);
      flipSum += reference::flip(ref, test, sc.points.width, sc.points.height).mean;
    }
    r.flip = flipSum / views;
  }
  if (keep) *keep = e;

  if (peersInto && opt.peers && sc.scene.triangles) {
    const CascadeStackImage img = st.stack->stackImage();
    const PeerRays rays = probeRaySet(gi, img, cfg.probes, in, frame);
    EmbreeScene embree(*sc.scene.triangles);
    PeerInputs pi;
    pi.context = &sc.ctx;
    pi.stack = st.stack.get();
    pi.allSlots = st.allSlots;
    pi.triangles = sc.scene.triangles.get();
    pi.embree = &embree;
    pi.voxelSize = sc.scene.voxelSize;
    pi.maxSteps = cfg.probes.maxSteps;
    pi.hitEpsilon = cfg.probes.hitEpsilon;
    pi.runs = opt.quick ? 2 : 3;
    std::printf("    peers on %zu probe rays of frame %llu (%s)\n", rays.origin.size(),
                (unsigned long long)frame, cfg.name.c_str());
    peersInto->peers = runPeers(pi, rays);
    peersInto->peerRays = rays.origin.size();
    peersInto->peerRaySet = "every probe not off of the '" + cfg.name + "' configuration (" +
                            std::to_string(cfg.cascades) +
                            (cfg.cascades == 1 ? " cascade, " : " cascades, ") +
                            std::to_string(cfg.probes.raysPerProbe) +
                            " rays each, that frame's rotation), bounded by the coarsest cascade";
  }

  // Light switch: off for offFrames, then on again. Converged = 95% of the switch's effect
  // recovered beyond the field's own jitter: mean |E_t - E_on| <= 0.05 mean |E_on - E_off| +
  // mean |E_on' - E_on| (E_on, E_on' two consecutive converged frames; E_off the last dark
  // frame; luminance at <= 1024 test points). Measured against the change, not against E: where
  // the sky dominates (outdoors) a sun switch is a few percent of E and would "converge" at once.
  r.convergeCap = cfg.converge ? opt.convergeCap : 0;
  if (r.convergeCap > 0 && !sc.scene.lights.lights.empty() && !sc.testQueries.empty()) {
    auto lum = [&] {
      std::vector<double> v;
      for (const glm::vec3& c : gi.irradiance(sc.testQueries)) v.push_back(luminance(c));
      return v;
    };
    auto meanAbsDiff = [](const std::vector<double>& a, const std::vector<double>& b) {
      double d = 0.0;
      for (std::size_t i = 0; i < a.size(); ++i) d += std::abs(a[i] - b[i]);
      return d / double(a.size());
    };
    const std::vector<double> on = lum();
    step();
    const double jitter = meanAbsDiff(lum(), on);
    SceneLights off = sc.scene.lights;
    off.lights.clear();
    off.version = 1;
    lights = off;
    for (int i = 0; i < opt.offFrames; ++i) step();
    const double change = meanAbsDiff(lum(), on);
    lights = sc.scene.lights;
    lights.version = 2;
    for (int k = 1; k <= r.convergeCap; ++k) {
      const GiFrameStats s = step();
      if (k == 1) r.lightRelightMs = s.lightMilliseconds;
      if (meanAbsDiff(lum(), on) <= 0.05 * change + jitter) {
        r.framesToConverge = k;
        break;
      }
    }
  }
  r.wallSeconds = secondsSince(start);
  return r;
}

SceneReport runScene(gpu::Context& ctx, const Options& opt, const std::string& name) {
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
  const std::vector<GiConfig> configs =
      opt.gpuTable ? std::vector<GiConfig>{} : sweepConfigs(*scene, opt.quick);
  std::vector<GiConfig> run = configs;
  if (opt.gpuTable) {
    // SDFDDGI's Sponza grid is 22 x 14 x 32 = 9,856 probes; our grids are 17³ per cascade at one
    // probe per brick, so 2 cascades (9,826 probes) is the nearest count we can run.
    ProbeFieldSettings def;
    run.push_back({"sdfddgi-probe-count", "ours", "2 cascades x 17³ = 9,826 probes", def, 2, false,
                   "default"});
    run.push_back({"default", "ours", "", def, scene->defaultCascades, false, ""});
    run.push_back({"plain-ddgi", "plain-ddgi", "", plainDdgi(), scene->defaultCascades, false, ""});
  }
  if (!opt.only.empty())
    std::erase_if(run, [&](const GiConfig& c) {
      return std::find(opt.only.begin(), opt.only.end(), c.name) == opt.only.end();
    });
  for (const GiConfig& c : run)
    if (!stacks.count(c.cascades))
      stacks.emplace(c.cascades, streamStack(store, loader, *scene, c.cascades));

  ViewPoints points;
  if (scene->triangles) {
    const auto refStart = Clock::now();
    reference::PathTracer tracer(*scene->triangles, scene->lights);
    EmbreeScene embree(*scene->triangles);
    points = visiblePoints(*scene, tracer, embree, opt.width, opt.height);
    if (!opt.gpuTable) {
      reference::CacheOutcome outcome;
      const auto est = reference::cachedIrradiance(
          opt.out / "reference", tracer, points.position, points.normal, opt.samples,
          reference::IrradianceKind::NoDirectLights, &outcome);
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
      std::printf(
          "  reference: %zu points x %u paths (%s, %.1f s); its own noise, as relMSE: %.2e\n",
          points.position.size(), opt.samples, rep.referenceCache.c_str(), rep.referenceSeconds,
          rep.referenceNoise);
      // A second, independent reference (another seed, same samples): how far two references
      // differ is the floor below which differences between configurations are noise.
      reference::PathTracerSettings other;
      other.seed = 2;
      reference::PathTracer tracer2(*scene->triangles, scene->lights, other);
      const auto est2 = reference::cachedIrradiance(opt.out / "reference", tracer2, points.position,
                                                    points.normal, opt.samples,
                                                    reference::IrradianceKind::NoDirectLights);
      std::vector<glm::vec3> second;
      for (const auto& x : est2) second.push_back(x.mean);
      rep.floorRelMSE = reference::relMSE(second, points.reference);
      for (std::size_t k = 0; k + 1 < points.start.size(); ++k) {
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
                         double(points.start.size() - 1);
      }
      std::printf("  two independent references differ by relMSE %.4f, FLIP %.4f (noise floor)\n",
                  rep.floorRelMSE, rep.floorFlip);
    }
  } else {
    const StreamedStack& st = stacks.begin()->second;
    points = sdfVisiblePoints(ctx, *scene, *st.stack, st.allSlots, opt.width, opt.height);
  }
  rep.points = points.position.size();
  rep.views = int(points.start.size()) - 1;
  rep.width = opt.width;
  rep.height = opt.height;

  SceneContext sc{ctx, opt, *scene, stacks, points, {}, {}, {}};
  const StreamedStack& any = stacks.begin()->second;
  const CascadeStackImage img = any.stack->stackImage();
  for (std::size_t i = 0; i < points.position.size(); ++i) {
    std::size_t k = 0;
    while (points.start[k + 1] <= i) ++k;
    const glm::vec3 toCamera = glm::normalize(points.cameras[k].position - points.position[i]);
    // Half a LOD-0 voxel off the triangle, towards the viewer: where the SDF's own surface
    // is for open sheets (mesh_to_sdf.h: unsigned distance minus half a voxel), i.e. where the
    // GI's renderer would shade; the true irradiance barely changes over that distance.
    const glm::dvec3 at = glm::dvec3(points.position[i]) +
                          glm::dvec3(points.normal[i]) * (opt.queryOffsetVoxels * scene->voxelSize);
    gpu_shared::ProbeQuery q{glm::vec4(img.toStack(at), 0.0f), glm::vec4(points.normal[i], 0.0f),
                             glm::vec4(toCamera, 0.0f)};
    sc.queries.push_back(q);
  }
  const std::size_t stride = std::max<std::size_t>(1, points.position.size() / 1024);
  for (std::size_t i = 0; i < points.position.size(); i += stride) {
    sc.testQueries.push_back(sc.queries[i]);
    sc.testIndex.push_back(i);
  }

  for (const GiConfig& c : run) {
    std::vector<glm::vec3> e;
    const bool isDefault = c.name == "default", isBaseline = c.name == "plain-ddgi";
    ConfigResult r = runConfig(sc, c, &e, isDefault && !opt.gpuTable ? &rep : nullptr);
    std::printf(
        "    %-22s update %8.2f ms  sample %7.2f ms  relMSE %8.4f  FLIP %.4f  E/Eref %.3f  "
        "converge %3d  %6.1f MiB  (%.0f s)\n",
        c.name.c_str(), r.updateMs, r.sampleMs, r.relMSE, r.flip, r.energyRatio, r.framesToConverge,
        r.memoryMiB(), r.wallSeconds);
    std::fflush(stdout);
    if ((isDefault || isBaseline) && !points.reference.empty())
      for (std::size_t k = 0; k + 1 < points.start.size(); ++k)
        writeToneMappedPng(sceneDir / (points.names[k] + "-" + c.name + ".png"),
                           shadedImage(points, k, e), points.width, points.height,
                           points.exposure[k]);
    rep.configs.push_back(std::move(r));
  }
  rep.seconds = secondsSince(start);
  return rep;
}

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

constexpr const char* kHelp =
    "usage: sdfstream bench gi [--quick] [--scenes a,b,...] [--out DIR] [--data DIR]\n"
    "                          [--large-world PACK] [--width W --height H] [--samples N]\n"
    "                          [--frames N] [--measure N] [--no-peers] [--gpu-table]\n"
    "                          [--device NAME]\n"
    "\n"
    "Run time vs error of the probe GI (issue 6). For each scene: import its triangles to a\n"
    "world pack (cached in DIR/packs), stream cascade stacks around the player, path-trace the\n"
    "reference irradiance at the visible points of the scene's views (kind NoDirectLights:\n"
    "what probes store; cached in DIR/reference), then for every configuration of the sweep\n"
    "(rays per probe, probe spacing, cascades, hit cache, states, relocation, visibility; our\n"
    "default; plain DDGI = one probe per brick, no relocation/states/hit cache, Chebyshev only)\n"
    "run the GI to convergence and measure GPU time per frame (probe update and sampling, medians\n"
    "of the pass timestamps), relMSE (top 0.1% discarded) and mean FLIP of albedo/pi*E images,\n"
    "frames to converge after the lights switch off and on, and device memory. The probe rays of\n"
    "one frame are also traced by Embree, OpenVDB and NanoVDB (2 threads) against our GPU\n"
    "traversal. Writes DIR/results.csv, DIR/summary.md, DIR/<scene>/error-vs-time.png and\n"
    "reference/default/plain-DDGI images per view.\n"
    "\n"
    "  --quick        Cornell box + one small scene (Breakfast Room, else the bunny), a reduced\n"
    "                 sweep, 96x72 views, 256 reference paths, fewer frames (<= 10 min on 2 "
    "cores)\n"
    "  --scenes LIST  cornell-box,sponza,breakfast-room,bunny,large-world (default: all of them;\n"
    "                 missing data is skipped with a message)\n"
    "  --out DIR      default out/bench-gi        --data DIR  default ../shared/data\n"
    "  --large-world  default out/worlds/large-4km (a pack; skipped when absent)\n"
    "  --frames N     warm-up frames per configuration (default 32, quick 8)\n"
    "  --measure N    measured frames (default 6, quick 4)\n"
    "  --samples N    reference paths per point (default 512, quick 256)\n"
    "  --no-peers     skip the traversal peers\n"
    "  --configs LIST run only these configurations (names as in results.csv)\n"
    "  --converge-cap N  most frames waited for convergence after the light change (0: skip)\n"
    "  --verbose      print every measured frame's pass times and work\n"
    "  --query-offset V  GI queries sit V LOD-0 voxels off the reference's points along the\n"
    "                 normal (default 0.5: on the SDF surface of an open sheet)\n"
    "  --gpu-table    only the per-pass time table of scripts/bench-gpu (SDFDDGI's probe count,\n"
    "                 our default, plain DDGI) on the given scenes; writes DIR/gpu-table.md\n";

}  // namespace

int runBenchGi(int argc, char** argv) {
  Args args(
      argc, argv, 3,
      {"--scenes", "--out", "-o", "--data", "--large-world", "--width", "--height", "--samples",
       "--frames", "--measure", "--device", "--converge-cap", "--configs", "--query-offset"},
      {"--help", "-h", "--quick", "--no-peers", "--gpu-table", "--validation", "--verbose"});
  if (args.has("--help") || args.has("-h")) {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (!args.positional().empty())
    throw InputError(InputErrorKind::Usage, "command line",
                     "bench gi takes no positional arguments (see --help)");
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines reach a pipe as they happen
  const auto start = Clock::now();
  Options opt;
  opt.quick = args.has("--quick");
  opt.gpuTable = args.has("--gpu-table");
  opt.peers = !args.has("--no-peers") && !opt.gpuTable;
  opt.verbose = args.has("--verbose");
  if (auto c = args.value("--configs")) opt.only = splitList(*c);
  opt.out = args.value("--out").value_or(args.value("-o").value_or(opt.out.string()));
  opt.data = args.value("--data").value_or(opt.data.string());
  opt.largeWorld = args.value("--large-world").value_or(opt.largeWorld.string());
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
  }
  opt.width = args.integer("--width", opt.width, 8, 8192);
  opt.height = args.integer("--height", opt.height, 8, 8192);
  opt.samples = std::uint32_t(args.integer("--samples", int(opt.samples), 1, 1 << 20));
  opt.warmup = args.integer("--frames", opt.warmup, 1, 100000);
  opt.measured = args.integer("--measure", opt.measured, 1, 1000);
  opt.convergeCap = args.integer("--converge-cap", opt.convergeCap, 0, 100000);
  opt.queryOffsetVoxels = args.number("--query-offset", opt.queryOffsetVoxels);
  if (auto s = args.value("--scenes")) {
    opt.scenes = splitList(*s);
  } else if (opt.quick) {
    opt.scenes = {"cornell-box",
                  fs::exists(opt.data / "breakfast-room") ? "breakfast-room" : "bunny"};
  } else if (opt.gpuTable) {
    opt.scenes = {"sponza"};
  } else {
    opt.scenes = {"cornell-box", "sponza", "breakfast-room", "large-world"};
  }

  for (const std::string& name : opt.scenes)
    if (std::find(benchSceneNames().begin(), benchSceneNames().end(), name) ==
        benchSceneNames().end())
      throw InputError(
          InputErrorKind::Usage, "command line",
          "unknown scene '" + name + "' (cornell-box, sponza, breakfast-room, large-world, bunny)");

  std::unique_ptr<gpu::Context> context = gpuContextFromArgs(args);
  if (!context)
    throw InputError(InputErrorKind::Usage, "command line", "bench gi needs a GPU (no --cpu)");
  RunInfo info;
  info.device = context->deviceName();
  info.mode = opt.gpuTable ? "gpu-table" : opt.quick ? "quick" : "full";
  for (int i = 1; i < argc; ++i) info.command += (i > 1 ? " " : "") + std::string(argv[i]);
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

}  // namespace sdfstream::cli
