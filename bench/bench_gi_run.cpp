#include "bench/bench_gi_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <span>
#include <string>

#include "bench/bench_gi_config_run.h"
#include "bench/bench_gi_diagnose.h"
#include "core/stats.h"
#include "core/stopwatch.h"
#include "demo/frame_image.h"
#include "gi/gi_system.h"
#include "gi/light_cache.h"
#include "gi/probe_math.h"
#include "gi/scene_lights.h"
#include "reference/flat_regions.h"
#include "reference/irradiance_cache.h"
#include "reference/metrics.h"
#include "reference/path_tracer.h"

namespace sdfstream::bench {
namespace {

using Clock = std::chrono::steady_clock;

double bufferMiB(std::initializer_list<const gpu::Buffer*> buffers) {
  double bytes = 0.0;
  for (const gpu::Buffer* b : buffers) bytes += double(b->size());
  return bytes / double(1 << 20);
}

// The configuration's own columns of its result row.
ConfigResult describe(const GiConfig& cfg) {
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
  return r;
}

// relMSE, the energy ratio and FLIP of the irradiance e at every point against the reference.
void score(const ViewPoints& points, const std::vector<glm::vec3>& e, ConfigResult& r) {
  r.relMSE = reference::relMSE(e, points.reference);
  double sumGi = 0.0, sumRef = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    sumGi += luminance(e[i]);
    sumRef += luminance(points.reference[i]);
  }
  r.energyRatio = sumRef > 0.0 ? sumGi / sumRef : 0.0;
  // Flat regions: normals within ~1° and plane offsets within 1 cm (positions are metres).
  const reference::FlatSpread flat = reference::flatRegionSpread(
      points.position, points.normal, points.start, e, points.reference, 0.01);
  r.flatSpread = flat.gi;
  r.flatSpreadReference = flat.reference;
  double flipSum = 0.0;
  for (std::size_t k = 0; k < points.views(); ++k) {
    const auto ref =
        reference::toneMapAces(shadedImage(points, k, points.reference), points.exposure[k]);
    const auto test = reference::toneMapAces(shadedImage(points, k, e), points.exposure[k]);
    flipSum += reference::flip(ref, test, points.width, points.height).mean;
  }
  r.flip = flipSum / double(std::max<std::size_t>(1, points.views()));
}

}  // namespace

// Global probe g (cascade * perVolume + storage index) of frame f, its data d (offset, state).
LiveProbe probeAt(const probe::ProbeFieldFrame& f, std::uint32_t perVolume, std::uint32_t g,
                  glm::vec4 d) {
  const std::uint32_t c = g / perVolume, st = g % perVolume;
  const gpu_shared::ProbeVolume& v = f.volumes[c];
  const glm::ivec3 counts(v.countsRays);
  const glm::ivec3 storage(int(st % counts.x), int(st / counts.x % counts.y),
                           int(st / (counts.x * counts.y)));
  const glm::ivec3 logical = (storage - glm::ivec3(v.scroll) + counts) % counts;
  return {glm::vec3(v.originSpacing) + glm::vec3(logical) * v.originSpacing.w + glm::vec3(d), c,
          std::uint32_t(logical.x + counts.x * (logical.y + counts.y * logical.z))};
}

// Every probe of `gi` that is not off.
std::vector<LiveProbe> liveProbes(const GiSystem& gi, const probe::ProbeFieldFrame& f,
                                  std::uint32_t perVolume) {
  const std::vector<glm::vec4> data = gi.probes().downloadProbeData();
  std::vector<LiveProbe> out;
  for (std::uint32_t g = 0; g < std::uint32_t(f.volumes.size()) * perVolume; ++g)
    if (std::uint32_t(data[g].w) != gpu_shared::kProbeOff)
      out.push_back(probeAt(f, perVolume, g, data[g]));
  return out;
}

// The probes of the receivers' cages (the 8 grid corners around each query in the cascade it is
// sampled from), as cascade * perVolume + logical cell.
std::set<std::uint32_t> cageProbes(const probe::ProbeFieldFrame& f, std::uint32_t perVolume,
                                   std::span<const gpu_shared::ProbeQuery> queries) {
  const std::vector<std::uint32_t> picks = samplingCascades(f.volumes, queries);
  std::set<std::uint32_t> out;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const gpu_shared::ProbeVolume& v = f.volumes[picks[i]];
    const glm::ivec3 counts(v.countsRays);
    const glm::ivec3 base = glm::clamp(
        glm::ivec3(glm::floor((glm::vec3(queries[i].position) - glm::vec3(v.originSpacing)) /
                              v.originSpacing.w)),
        glm::ivec3(0), glm::max(counts - 2, glm::ivec3(0)));
    for (int corner = 0; corner < 8; ++corner) {
      const glm::ivec3 lc =
          glm::min(base + glm::ivec3(corner & 1, corner >> 1 & 1, corner >> 2 & 1), counts - 1);
      out.insert(picks[i] * perVolume + std::uint32_t(lc.x + counts.x * (lc.y + counts.y * lc.z)));
    }
  }
  return out;
}

// Where a ray from o along unit dir leaves the box [lo, hi] (o inside; 0 when it starts outside).
float boxExit(glm::vec3 lo, glm::vec3 hi, glm::vec3 o, glm::vec3 dir) {
  float tExit = 1e30f;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(dir[a]) < 1e-12f) continue;
    const float t = ((dir[a] > 0.0f ? hi[a] : lo[a]) - o[a]) / dir[a];
    tExit = std::min(tExit, std::max(t, 0.0f));
  }
  return tExit;
}

// Probe rays of one frame of `gi` (every probe that is not off, raysPerProbe rays each, one
// rotation of the pattern: slot frame mod slots), in both frames, bounded by the coarsest
// cascade's window.
PeerRays probeRaySet(const GiSystem& gi, const CascadeStackImage& img,
                     const probe::ProbeFieldSettings& s, const probe::ProbeFrameInputs& in,
                     std::uint64_t frame) {
  probe::ProbeFieldFrameBuilder builder(s);
  const probe::ProbeFieldFrame f = builder.build(img, in, frame);
  const std::uint32_t perVolume = s.probesPerVolume(), n = s.raysPerProbe;
  const gpu_shared::CascadeTraceParams& last = img.params.back();
  const glm::vec3 lo(last.offsetScale), hi = lo + glm::vec3(128.0f * last.offsetScale.w);
  const std::size_t slot = frame % std::max(1u, f.constants.selection.z);
  const std::vector<glm::vec4>& pattern = *f.rayPattern;
  const glm::mat3 rot{glm::vec3(pattern[3 * slot]), glm::vec3(pattern[3 * slot + 1]),
                      glm::vec3(pattern[3 * slot + 2])};
  PeerRays r;
  for (const LiveProbe& p : liveProbes(gi, f, perVolume)) {
    const glm::vec3 o = p.stack;
    for (std::uint32_t i = 0; i < n; ++i) {
      const glm::vec3 dir = probe::rayDirection(i, n, rot);
      const float tExit = boxExit(lo, hi, o, dir);  // the coarsest window: every peer's bound
      gpu_shared::TraceRay tr;
      tr.originTMin = glm::vec4(o, 0.0f);
      tr.dirTMax = glm::vec4(dir, tExit);
      r.stack.push_back(tr);
      r.origin.push_back(glm::vec3(img.cascade0MinWorld + glm::dvec3(o) * img.voxelSize0));
      r.direction.push_back(dir);
      r.tMax.push_back(float(double(tExit) * img.voxelSize0));
      r.cascade.push_back(p.cascade);
      r.probeCell.push_back(p.cell);
    }
  }
  return r;
}

// The measured frames: medians of the pass times and work, and device memory, into r. Returns
// the last frame's irradiance at every point.
std::vector<glm::vec3> ConfigRun::measure(ConfigResult& r) {
  const GiBenchOptions& opt = sc_.opt;
  std::map<std::string, std::vector<double>> passes;
  std::vector<double> update, sample, probesUpdated, raysTraced, raysCached, steps;
  std::vector<glm::vec3> e;
  for (int m = 0; m < opt.measured; ++m) {
    const GiFrameStats s = step();
    double total = 0.0;
    for (const auto& t : gi_.probes().lastTimings()) {
      passes[t.name].push_back(t.milliseconds);
      total += t.milliseconds;
      if (opt.verbose)
        std::printf("      frame %llu %s %.2f ms\n", (unsigned long long)frame_ - 1, t.name.c_str(),
                    t.milliseconds);
    }
    if (opt.verbose)
      std::printf(
          "      frame %llu: %u probes, %u rays traced, %u cached, %llu steps, %u bounce cells "
          "looked up, %u rays waited for one or looked up their own (%u their own); states "
          "off %u, sleeping %u, awake %u, vigilant %u\n",
          (unsigned long long)frame_ - 1, s.probes.probesUpdated, s.probes.raysTraced,
          s.probes.raysCached, (unsigned long long)s.probes.steps, s.probes.bounceCells,
          s.probes.bounceRays, s.probes.bounceOwn, s.probes.states[gpu_shared::kProbeOff],
          s.probes.states[gpu_shared::kProbeSleeping], s.probes.states[gpu_shared::kProbeAwake],
          s.probes.states[gpu_shared::kProbeVigilant]);
    update.push_back(total);
    std::copy(std::begin(s.probes.states), std::end(s.probes.states), r.probeStates.begin());
    probesUpdated.push_back(s.probes.probesUpdated);
    raysTraced.push_back(s.probes.raysTraced);
    raysCached.push_back(s.probes.raysCached);
    steps.push_back(double(s.probes.steps));
    if (cfg_.sampleBlock > 1) {
      e.resize(sc_.queries.size());
      const ViewPoints& p = sc_.points;
      const std::uint32_t width = std::uint32_t(std::max(p.width, 1));
      const std::uint32_t height = std::uint32_t(std::max(p.height, 1));
      const std::size_t pixels = std::size_t(width) * height;
      double ms = 0.0;
      for (std::size_t k = 0; k < p.views(); ++k) {
        const std::vector<glm::vec3> image =
            gi_.irradianceHalfResolution(std::span(sc_.imageQueries).subspan(k * pixels, pixels),
                                         width, height, cfg_.sampleBlock);
        ms += gi_.lastSampleMilliseconds();
        for (std::size_t i = p.start[k]; i < p.start[k + 1]; ++i)
          e[i] = image[std::size_t(p.pixel[i])];
      }
      sample.push_back(ms);
    } else {
      const std::vector<glm::vec3> tiled = gi_.irradiance(sc_.sampleQueries);
      sample.push_back(gi_.lastSampleMilliseconds());
      e.resize(tiled.size());
      for (std::size_t k = 0; k < tiled.size(); ++k) e[sc_.sampleOrder[k]] = tiled[k];
    }
    if (opt.verbose && !sc_.points.reference.empty())
      std::printf("      frame %llu: relMSE %.4f\n", (unsigned long long)frame_ - 1,
                  reference::relMSE(e, sc_.points.reference));
  }
  if (cfg_.sampleBlock > 1 && !e.empty()) {
    const std::vector<glm::vec3> tiled = gi_.irradiance(sc_.sampleQueries);
    std::vector<glm::vec3> full(tiled.size());
    for (std::size_t k = 0; k < tiled.size(); ++k) full[sc_.sampleOrder[k]] = tiled[k];
    r.halfVsFullRelMSE = reference::relMSE(e, full);
    std::printf("    %s: against full-resolution sampling of the same field, relMSE %.5f\n",
                cfg_.name.c_str(), r.halfVsFullRelMSE);
  }
  for (auto& [name, v] : passes) r.passMs[name] = median(v);
  const double views = double(std::max<std::size_t>(1, sc_.points.views()));
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
  r.sampleNsPerQuery =
      sc_.queries.empty() ? 0.0 : median(sample) * 1e6 / double(sc_.queries.size());
  r.probesUpdated = median(probesUpdated);
  r.raysTraced = median(raysTraced);
  r.raysCached = median(raysCached);
  r.steps = median(steps);
  r.probeMiB = double(gi_.probes().deviceBytes()) / double(1 << 20);
  r.lightMiB = bufferMiB({&gi_.lightCache().radianceBuffer()});
  const GpuStackScene& g = gi_.scene();
  r.atlasMiB = bufferMiB(
      {&g.pageTables(), &g.distance(), &g.corners(), &g.albedo(), &g.emission(), &g.params()});
  return e;
}

// The reference irradiance (NoDirectLights, cached with the scene's) at world points.
std::vector<glm::vec3> ConfigRun::referenceAt(std::span<const glm::vec3> positions,
                                              std::span<const glm::vec3> normals,
                                              std::uint32_t maxDepth) const {
  reference::PathTracerSettings settings;
  settings.maxDepth = maxDepth;
  const reference::PathTracer tracer(*sc_.scene.triangles, sc_.scene.lights, settings);
  std::vector<glm::vec3> out;
  for (const auto& x :
       reference::cachedIrradiance(sc_.opt.out / "reference", tracer, positions, normals,
                                   sc_.opt.samples, reference::IrradianceKind::NoDirectLights))
    out.push_back(x.mean);
  return out;
}

// The traversal peers on this frame's probe rays.
void ConfigRun::runPeersOnProbeRays(SceneReport& into) {
  const CascadeStackImage img = st_.stack->stackImage();
  const PeerRays rays = probeRaySet(gi_, img, cfg_.probes, in_, frame_);
  EmbreeScene embree(*sc_.scene.triangles);
  PeerInputs pi = peerInputs(embree);
  pi.runs = sc_.opt.quick ? 2 : 3;
  std::printf("    peers on %zu probe rays of frame %llu (%s)\n", rays.origin.size(),
              (unsigned long long)frame_, cfg_.name.c_str());
  into.peers = runPeers(pi, rays);
  into.peerRays = rays.origin.size();
  into.peerRaySet = "every probe not off of the '" + cfg_.name + "' configuration (" +
                    std::to_string(cfg_.cascades) +
                    (cfg_.cascades == 1 ? " cascade, " : " cascades, ") +
                    std::to_string(cfg_.probes.raysPerProbe) +
                    " rays each, that frame's rotation), bounded by the coarsest cascade";
}

// Light switch, once the field has settled after the first frames' vigilance: off for
// offFrames, then on again.
// Converged = 95% of the switch's effect recovered beyond the field's own jitter:
// mean |E_t - E_on| <= 0.05 mean |E_on - E_off| +
// mean |E_on' - E_on| (E_on, E_on' two consecutive converged frames; E_off the last dark
// frame; luminance at <= 1024 test points). Measured against the change, not against E: where
// the sky dominates (outdoors) a sun switch is a few percent of E and would "converge" at once.
void ConfigRun::measureConvergence(ConfigResult& r) {
  auto lum = [&] {
    std::vector<double> v;
    for (const glm::vec3& c : gi_.irradiance(sc_.testQueries)) v.push_back(luminance(c));
    return v;
  };
  auto meanAbsDiff = [](const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) d += std::abs(a[i] - b[i]);
    return d / double(a.size());
  };
  // E_on must be the field the lights settle to. A new probe's vigilance (its first
  // vigilantFrames updates) leaves a texel holding mostly its last hit-cache rotation's estimate,
  // which the calm hysteresis (0.97) averages away over tens of frames: judged against that
  // rotation's bias, a switch would seem to converge only on frames of the same rotation
  // (docs/DECISIONS.md, "A light switch: ..."). 64 calm frames leave 0.97^64 = 0.14 of it.
  const std::uint64_t settled = std::uint64_t(cfg_.probes.vigilantFrames) + 64u;
  while (frame_ < settled) step();
  const std::vector<double> on = lum();
  step();
  const double jitter = meanAbsDiff(lum(), on);
  SceneLights off = sc_.scene.lights;
  off.lights.clear();
  off.version = 1;
  lights_ = off;
  for (int i = 0; i < sc_.opt.offFrames; ++i) step();
  const double change = meanAbsDiff(lum(), on);
  lights_ = sc_.scene.lights;
  lights_.version = 2;
  for (int k = 1; k <= r.convergeCap; ++k) {
    const GiFrameStats s = step();
    if (k == 1) r.lightRelightMs = s.lightMilliseconds;
    const double left = meanAbsDiff(lum(), on);
    if (sc_.opt.verbose)
      std::printf(
          "      light switch, frame %d: %.4f of the change left (jitter %.4f), probe passes "
          "%.3f ms\n",
          k, left / std::max(change, 1e-30), jitter / std::max(change, 1e-30), s.probeMilliseconds);
    if (left <= 0.05 * change + jitter) {
      r.framesToConverge = k;
      break;
    }
  }
}

double ConfigRun::measureRelightMs(int repeats) {
  std::vector<double> ms;
  for (int i = 0; i < repeats; ++i) {
    ++lights_.version;
    ms.push_back(step().lightMilliseconds);
  }
  return median(std::move(ms));
}

LightCacheWork ConfigRun::lightWork() const {
  const CascadeStackImage img = st_.stack->stackImage();
  return lightCacheWork(img, toGpu(lights_.lights, img));
}

void ConfigRun::measureMovingSun(std::uint32_t pageBudget, int warmup, int frames,
                                 ConfigResult& r) {
  gi_.setRelightPageBudget(pageBudget);
  ConfigResult::MovingSun row;
  row.budget = pageBudget;
  std::vector<double> ms;
  for (int i = 0; i < warmup + frames; ++i) {
    ++lights_.version;
    const GiFrameStats s = step();
    if (i < warmup) continue;
    ms.push_back(s.lightMilliseconds);
    row.stalenessFrames = std::max(row.stalenessFrames, s.relight.maxStalenessFrames);
    row.residentPages = s.relight.selected + s.relight.pending;
  }
  gi_.setRelightPageBudget(kRelightEveryPage);
  row.lightMs = median(std::move(ms));
  r.movingSun.push_back(row);
}

ConfigResult runConfig(SceneContext& sc, const GiConfig& cfg, std::vector<glm::vec3>* keep,
                       const RunReports& into) {
  const auto start = Clock::now();
  const GiBenchOptions& opt = sc.opt;
  ConfigRun run(sc, cfg);
  ConfigResult r = describe(cfg);
  const GiFrameStats first = run.step();
  r.lightRelightMs = first.lightMilliseconds;
  for (int i = 1; i < opt.warmup; ++i) run.step();
  if (sc.warmGpu) sc.warmGpu();
  const std::vector<glm::vec3> e = run.measure(r);
  if (!sc.points.reference.empty()) score(sc.points, e, r);
  if (opt.gpuTable && opt.settledFrames > 0 && run.frame() < std::uint64_t(opt.settledFrames)) {
    while (run.frame() < std::uint64_t(opt.settledFrames)) run.step();
    if (sc.warmGpu) sc.warmGpu();
    ConfigResult later = describe(cfg);
    run.measure(later);
    r.settled.afterFrames = std::uint64_t(opt.settledFrames);
    r.settled.updateMs = later.updateMs;
    r.settled.sampleMs = later.sampleMs;
    r.settled.probesUpdated = later.probesUpdated;
    r.settled.raysTraced = later.raysTraced;
    r.settled.raysCached = later.raysCached;
    r.settled.passMs = later.passMs;
    r.settled.probeStates = later.probeStates;
  }
  if (opt.gpuTable) {
    r.lightRelightWarmMs = run.measureRelightMs(5);
    r.lightWork = run.lightWork();
    // fly's budget on a GPU (resolveDeviceBudgets) and twice and four times it; the queue settles
    // within ceil(resident / budget) frames (Sponza: up to 57 at 256 pages).
    for (std::uint32_t budget : {256u, 512u, 1024u}) run.measureMovingSun(budget, 64, 16, r);
  }
  if (keep) *keep = e;
  if (into.peers && sc.scene.triangles) run.runPeersOnProbeRays(*into.peers);
  if (into.diagnosis && sc.scene.triangles) run.diagnoseRays(*into.diagnosis);
  if (into.rayRadiance && sc.scene.triangles) run.diagnoseRayRadiance(*into.rayRadiance);
  r.convergeCap = cfg.converge ? opt.convergeCap : 0;
  if (r.convergeCap > 0 && !sc.scene.lights.lights.empty() && !sc.testQueries.empty())
    run.measureConvergence(r);
  r.wallSeconds = secondsSince(start);
  return r;
}

}  // namespace sdfstream::bench
