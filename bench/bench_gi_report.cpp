#include "bench/bench_gi_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/atomic_dir.h"
#include "demo/plot.h"

namespace sdfstream::bench {
namespace {

namespace fs = std::filesystem;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

bool hasError(const ConfigResult& c) { return c.relMSE >= 0.0; }

// a dominates b: no worse on both axes, better on one. Axes: frame time and relMSE (memory
// instead of relMSE when there is no reference).
bool dominates(const ConfigResult& a, const ConfigResult& b) {
  const double ea = hasError(a) ? a.relMSE : a.memoryMiB();
  const double eb = hasError(b) ? b.relMSE : b.memoryMiB();
  return a.frameMs <= b.frameMs && ea <= eb && (a.frameMs < b.frameMs || ea < eb);
}

void markPareto(std::vector<ConfigResult>& configs) {
  for (ConfigResult& c : configs) {
    c.pareto = true;
    for (const ConfigResult& o : configs)
      if (&o != &c && dominates(o, c)) c.pareto = false;
  }
}

const ConfigResult* find(const SceneReport& s, const std::string& name) {
  for (const ConfigResult& c : s.configs)
    if (c.config == name) return &c;
  return nullptr;
}

std::string yesNo(bool b) { return b ? "on" : "off"; }

std::string converge(const ConfigResult& c) {
  if (c.convergeCap == 0) return "-";
  return c.framesToConverge < 0 ? "> " + std::to_string(c.convergeCap)
                                : std::to_string(c.framesToConverge);
}

std::string errorText(double v, const char* f = "%.4f") { return v < 0.0 ? "-" : fmt(f, v); }

std::string pct(double now, double base) {
  if (base == 0.0) return "-";
  return fmt("%+.0f%%", 100.0 * (now - base) / base);
}

// The plain statement the issue asks for: does our default dominate plain DDGI here, and if not,
// which axis it loses on and which of its switches cost that (from the one-switch ablations).
std::string verdict(const SceneReport& s) {
  const ConfigResult* d = find(s, "default");
  const ConfigResult* b = find(s, "plain-ddgi");
  if (!d || !b) return "default or plain-ddgi did not run.";
  if (!hasError(*d)) return "no reference on this scene: time and memory only (see the table).";
  std::ostringstream out;
  const bool dom = dominates(*d, *b);
  out << "**" << (dom ? "Yes" : "No") << "**: default " << fmt("%.2f", d->frameMs) << " ms, relMSE "
      << fmt("%.4f", d->relMSE) << " vs plain DDGI " << fmt("%.2f", b->frameMs) << " ms, relMSE "
      << fmt("%.4f", b->relMSE) << " (time " << pct(d->frameMs, b->frameMs) << ", relMSE "
      << pct(d->relMSE, b->relMSE) << ", FLIP " << fmt("%.4f", d->flip) << " vs "
      << fmt("%.4f", b->flip) << ").";
  const bool timeOrderUnsure = (d->frameMs < b->frameMs) != (d->frameBestMs < b->frameBestMs);
  if (timeOrderUnsure)
    out << " Caution: the best frames order the two the other way (" << fmt("%.2f", d->frameBestMs)
        << " vs " << fmt("%.2f", b->frameBestMs)
        << " ms): the time difference is within this machine's frame-to-frame noise.";
  if (std::abs(d->relMSE - b->relMSE) < s.floorRelMSE)
    out << " The relMSE difference is below the reference's own noise floor ("
        << fmt("%.4f", s.floorRelMSE) << ": two references of different seeds differ that much).";
  if (dom) return out.str();
  // Which single change from our configuration moves it towards the axis it loses on: the
  // switches (measured from the default, or from spacing 2 in quick mode), rays, spacing, cascades.
  auto culprits = [&](bool time) {
    std::vector<std::pair<double, std::string>> gains;
    for (const ConfigResult& c : s.configs) {
      if (c.family != "ours" || c.change.empty()) continue;
      const ConfigResult* base = find(s, c.base);
      if (!base) continue;
      const double now = time ? c.frameMs : c.relMSE, was = time ? base->frameMs : base->relMSE;
      if (now < was)
        gains.emplace_back((now - was) / was,
                           c.change + (c.base != "default" ? " (from " + c.base + ")" : ""));
    }
    std::sort(gains.begin(), gains.end());
    std::string text;
    for (const auto& [delta, name] : gains)
      text += (text.empty() ? "" : ", ") + name + " " + fmt("%+.0f%%", 100.0 * delta);
    return text.empty() ? std::string("no single change measured here") : text;
  };
  if (d->frameMs > b->frameMs)
    out << " It is slower; single changes that cut time: " << culprits(true) << ".";
  if (d->relMSE > b->relMSE)
    out << " It is less accurate; single changes that cut relMSE: " << culprits(false) << ".";
  return out.str();
}

void writePlot(const fs::path& path, const SceneReport& s) {
  Chart chart;
  const bool withError = !s.configs.empty() && hasError(s.configs.front());
  chart.title = s.name + ": " + (withError ? "relMSE" : "device MiB") + " vs GPU time per frame";
  chart.xLabel = "GPU ms per frame (probe update + sampling one view)";
  chart.yLabel = withError ? "relMSE of irradiance (top 0.1% discarded)" : "device memory (MiB)";
  auto y = [&](const ConfigResult& c) { return withError ? c.relMSE : c.memoryMiB(); };
  Series ours{"ours (sweep)", {}, {}, glm::vec3(0.15f, 0.4f, 0.85f), true};
  Series plain{"plain DDGI (rays 32..256)", {}, {}, glm::vec3(0.95f, 0.5f, 0.1f), true};
  Series def{"our default", {}, {}, glm::vec3(0.85f, 0.1f, 0.1f), true};
  Series base{"plain DDGI (128 rays)", {}, {}, glm::vec3(0.1f, 0.1f, 0.1f), true};
  Series front{"Pareto front", {}, {}, glm::vec3(0.1f, 0.65f, 0.25f), false};
  std::vector<const ConfigResult*> f;
  double lo = 1e300, hi = 0.0, ylo = 1e300, yhi = 0.0;
  for (const ConfigResult& c : s.configs) {
    Series& target = c.config == "default"      ? def
                     : c.config == "plain-ddgi" ? base
                     : c.family == "ours"       ? ours
                                                : plain;
    target.x.push_back(c.frameMs);
    target.y.push_back(y(c));
    if (c.pareto) f.push_back(&c);
    lo = std::min(lo, c.frameMs), hi = std::max(hi, c.frameMs);
    ylo = std::min(ylo, y(c)), yhi = std::max(yhi, y(c));
  }
  std::sort(f.begin(), f.end(), [](auto* a, auto* b) { return a->frameMs < b->frameMs; });
  for (const ConfigResult* c : f) {
    front.x.push_back(c->frameMs);
    front.y.push_back(y(*c));
  }
  chart.series = {front, ours, plain, base, def};
  chart.logX = lo > 0.0 && hi / lo > 20.0;
  chart.logY = ylo > 0.0 && yhi / ylo > 20.0;
  writeChartPng(path, chart, 900, 540);
}

void writeText(const fs::path& path, const std::string& text) {
  writeFileAtomically(path, text.data(), text.size());
}

// results.csv: one row per scene x configuration.
std::string resultsCsv(const std::vector<SceneReport>& scenes) {
  std::ostringstream csv;
  csv << "scene,config,family,rays,spacing_bricks,cascades,hit_cache,states,relocation,visibility,"
         "probes,update_ms,sample_ms,frame_ms,frame_best_ms,frame_worst_ms,sample_ns_per_query,"
         "light_relight_ms,classify_ms,"
         "select_ms,trace_ms,blend_ms,probes_updated,rays_traced,rays_cached,steps,"
         "relmse,flip,energy_ratio,frames_to_converge,probe_mib,light_mib,atlas_mib,memory_mib,"
         "pareto,"
         "wall_s,flat_spread,flat_spread_reference\n";
  for (const SceneReport& s : scenes)
    for (const ConfigResult& c : s.configs) {
      auto pass = [&](const char* n) {
        auto it = c.passMs.find(n);
        return it == c.passMs.end() ? 0.0 : it->second;
      };
      csv << s.name << ',' << c.config << ',' << c.family << ',' << c.rays << ',' << c.spacing
          << ',' << c.cascades << ',' << c.hitCache << ',' << c.states << ',' << c.relocation << ','
          << c.visibility << ',' << c.probes << ',' << c.updateMs << ',' << c.sampleMs << ','
          << c.frameMs << ',' << c.frameBestMs << ',' << c.frameWorstMs << ',' << c.sampleNsPerQuery
          << ',' << c.lightRelightMs << ',' << pass("probe_classify") << ','
          << pass("probe_select_count") + pass("probe_select_emit") + pass("probe_select_args")
          << ',' << pass("probe_trace") << ',' << pass("probe_blend") << ',' << c.probesUpdated
          << ',' << c.raysTraced << ',' << c.raysCached << ',' << c.steps << ',' << c.relMSE << ','
          << c.flip << ',' << c.energyRatio << ',' << c.framesToConverge << ',' << c.probeMiB << ','
          << c.lightMiB << ',' << c.atlasMiB << ',' << c.memoryMiB() << ',' << c.pareto << ','
          << c.wallSeconds << ',' << c.flatSpread << ',' << c.flatSpreadReference << '\n';
    }
  return csv.str();
}

// How everything below was measured.
void writeMethod(std::ostringstream& md, const RunInfo& run) {
  md << "# bench gi\n\n"
     << "`sdfstream " << run.command << "` — " << run.mode << " mode on **" << run.device << "**, "
     << fmt("%.0f", run.seconds) << " s in all. Every number below comes from this run.\n\n"
     << "- **Error**: irradiance E(x, n) of the probes (`GiSystem::irradiance`, all cascades "
        "blended) at the surface point seen through each pixel centre of each view, against the "
        "path-traced reference (`reference/path_tracer.h`, Embree on the source triangles) of "
        "kind *NoDirectLights* — everything except the delta lights' direct term at the point, "
        "which is what the probes store (the light cache shades probe-ray hits; direct light at "
        "a receiver is the renderer's job). **relMSE** per point and channel, mean over points "
        "with the **top 0.1% discarded** (ε = 0.01). **FLIP**: mean LDR-FLIP (67 ppd) between "
        "ACES-tone-mapped images of albedo/π·E (same exposure for both: 0.18 / mean reference "
        "luminance of the view).\n"
     << "- **Time**: GPU timestamps, median over the measured frames after the warm-up. "
        "*update* = every probe pass of one frame (classify, select count/emit, trace, bounce "
        "cells, blend with the tiles' borders); *sample* = `probe_sample` for one view's visible "
        "points; *frame* = update + "
        "sample. The light cache relights only dirty pages, i.e. nothing in a static frame: its "
        "full relight (all resident pages, the frame after a light change) is listed apart. On "
        "lavapipe all of this is CPU time on this machine's cores.\n"
     << "- **Converge**: the scene's lights off for a few frames, then on again: frames until "
        "95% of the switch's effect is recovered beyond the field's own jitter, i.e. mean |E_t − "
        "E_on| ≤ 0.05 · mean |E_on − E_off| + mean |E_on′ − E_on| over ≤ 1024 test points "
        "(luminance; E_on, E_on′ two consecutive converged frames, E_off the last dark one). "
        "Relative to the change rather than to E, so a sun switch under a bright sky is not "
        "'converged' at once. '-' = not measured (quick mode measures its ablation base only); "
        "'> N' = not within the cap.\n"
     << "- **Memory**: probe field buffers + light cache + the stack's device copy (page tables "
        "and the brick atlas, which the stack allocates at its full slot budget).\n"
     << "- **Plain DDGI** = the same code with one probe per brick, no relocation, no probe "
        "states, no hit cache, Chebyshev visibility only.\n\n";
}

// The verdict over all scenes, and what quick mode leaves out.
void writeVerdict(std::ostringstream& md, const std::vector<SceneReport>& scenes,
                  const RunInfo& run) {
  int dominated = 0, compared = 0;
  std::string list;
  for (const SceneReport& s : scenes) {
    const ConfigResult* d = find(s, "default");
    const ConfigResult* b = find(s, "plain-ddgi");
    if (d && b && hasError(*d)) {
      ++compared;
      dominated += dominates(*d, *b);
      list += (list.empty() ? "" : ", ") + s.name + ": " + (dominates(*d, *b) ? "yes" : "no");
    }
  }
  md << "**Verdict:** our default configuration Pareto-dominates plain DDGI (frame time and "
        "relMSE) on "
     << dominated << " of " << compared << " scenes with a reference"
     << (list.empty() ? "" : " (" + list + ")")
     << "; the issue asks for at least three. Per scene below: the numbers, and where it does not, "
        "why.\n\n";
  if (run.mode == "quick")
    md << "Quick mode: small views, 256 reference paths, 8 warm-up frames, 4 measured. On the "
          "Cornell box the relMSE at frame 8 is within 5% of frame 40's; a new field's first "
          "frames run several probe updates each, as after a light switch, so interiors lit "
          "through several bounces (the Breakfast Room: E/E_ref 0.942 at frame 8, 0.943 at "
          "frame 64) have built their bounces by then. Rays 32 and spacing 2/4 "
          "from "
          "the default; the switch ablations (hit cache, states, relocation, visibility) are made "
          "from spacing 2, the cheapest configuration that still resolves the scenes, and only "
          "spacing 2 measures convergence. The full mode runs them from the default.\n\n";
}

// Every configuration of a scene, fastest first, and its Pareto front.
void writeConfigTable(std::ostringstream& md, const SceneReport& s) {
  md << "| config | rays | spacing | casc. | hit cache | states | reloc. | visibility | probes | "
        "update ms | sample ms | frame ms | frame range | light relight ms | relMSE | FLIP | "
        "E/E_ref | converge | "
        "MiB | Pareto "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<const ConfigResult*> sorted;
  for (const ConfigResult& c : s.configs) sorted.push_back(&c);
  std::sort(sorted.begin(), sorted.end(), [](auto* a, auto* b) { return a->frameMs < b->frameMs; });
  for (const ConfigResult* c : sorted)
    md << "| "
       << (c->config == "default" || c->config == "plain-ddgi" ? "**" + c->config + "**"
                                                               : c->config)
       << " | " << c->rays << " | " << c->spacing << " | " << c->cascades << " | "
       << yesNo(c->hitCache) << " | " << yesNo(c->states) << " | " << yesNo(c->relocation) << " | "
       << c->visibility << " | " << c->probes << " | " << fmt("%.2f", c->updateMs) << " | "
       << fmt("%.2f", c->sampleMs) << " | " << fmt("%.2f", c->frameMs) << " | "
       << fmt("%.0f", c->frameBestMs) << "–" << fmt("%.0f", c->frameWorstMs) << " | "
       << fmt("%.1f", c->lightRelightMs) << " | " << errorText(c->relMSE) << " | "
       << errorText(c->flip) << " | " << (hasError(*c) ? fmt("%.2f", c->energyRatio) : "-") << " | "
       << converge(*c) << " | " << fmt("%.1f", c->memoryMiB()) << " | " << (c->pareto ? "●" : "")
       << " |\n";
  md << "\nPareto front (fastest first): ";
  bool firstFront = true;
  for (const ConfigResult* c : sorted)
    if (c->pareto) {
      md << (firstFront ? "" : " → ") << c->config;
      firstFront = false;
    }
  md << ".\n\n**Does our default Pareto-dominate plain DDGI here?** " << verdict(s) << "\n\n";
}

// The one-change-at-a-time table.
void writeAblations(std::ostringstream& md, const SceneReport& s) {
  md << "One change at a time (Δ vs the configuration it changes):\n\n| change | from | frame ms "
        "| relMSE | FLIP | converge | probes updated | rays traced | rays cached |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  for (const ConfigResult& c : s.configs) {
    const ConfigResult* base = find(s, c.base);
    if (c.change.empty() || !base) continue;
    md << "| " << c.change << " | " << c.base << " | " << pct(c.frameMs, base->frameMs) << " | "
       << (hasError(c) ? pct(c.relMSE, base->relMSE) : "-") << " | "
       << (hasError(c) ? pct(c.flip, base->flip) : "-") << " | " << converge(c) << " | "
       << fmt("%.0f", c.probesUpdated) << " | " << fmt("%.0f", c.raysTraced) << " | "
       << fmt("%.0f", c.raysCached) << " |\n";
  }
  md << "\n";
}

// The traversal peers on one frame's probe rays.
void writePeers(std::ostringstream& md, const SceneReport& s, const RunInfo& run) {
  const PeerResult* e = nullptr;
  for (const PeerResult& p : s.peers)
    if (p.name == "embree") e = &p;
  md << "Peers on one frame's probe rays: " << s.peerRays << " rays (" << s.peerRaySet
     << ").\n\n| traversal | where | ms (best) | MRays/s | × Embree | hits | hit/miss "
        "agreement with Embree | median abs(Δt) vs Embree (voxels) | p90 abs(Δt) |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  for (const PeerResult& p : s.peers)
    md << "| " << p.name << " | " << p.where << " | " << fmt("%.2f", p.milliseconds) << " | "
       << fmt("%.2f", p.mraysPerSecond) << " | "
       << (e ? fmt("%.2f", p.mraysPerSecond / e->mraysPerSecond) : "-") << " | " << p.hits << " | "
       << fmt("%.4f", p.agreement) << " | " << fmt("%.3f", p.medianAbsDtVoxels) << " | "
       << fmt("%.3f", p.p90AbsDtVoxels) << " |\n";
  md << "\nOur traversal's time is the GPU pass (timestamps) on " << run.device
     << "; the CPU peers' is wall time on 2 threads. The VDB peers read a level set of the "
        "same triangles at the pack's LOD-0 voxel and lattice (the importer's own sign "
        "rule); NanoVDB's ZeroCrossing stops at the first voxel of the crossing (no "
        "refinement), so its |Δt| is up to a voxel by design.\n\n";
}

// One scene's section (and its plot).
void writeScene(std::ostringstream& md, const SceneReport& s, const fs::path& outDir,
                const RunInfo& run) {
  md << "## " << s.name << "\n\n";
  if (!s.skipped.empty()) {
    md << "Skipped: " << s.skipped << "\n\n";
    return;
  }
  md << s.description << ". LOD-0 voxel " << fmt("%.4g", s.voxelSize) << " m, " << s.lods
     << " LODs; pack "
     << (s.importSeconds > 0 ? "imported in " + fmt("%.1f", s.importSeconds) + " s" : "cached")
     << ". " << s.views << " view(s) of " << s.width << "×" << s.height << ", " << s.points
     << " visible points. ";
  if (s.referenceSamples)
    md << "Reference: " << s.referenceSamples << " paths per point (" << s.referenceCache << ", "
       << fmt("%.1f", s.referenceSeconds) << " s); its own noise as a relMSE ≈ "
       << fmt("%.2e", s.referenceNoise)
       << "; a second reference with another seed differs from "
          "it by relMSE "
       << fmt("%.4f", s.floorRelMSE) << " and FLIP " << fmt("%.4f", s.floorFlip)
       << " — the noise floor of both metrics (FLIP reacts strongly to the reference's per-pixel "
          "noise, which the smooth GI does not have). ";
  md << "Warm-up " << s.warmupFrames << " frames, " << s.measuredFrames << " measured. Scene "
     << "total " << fmt("%.0f", s.seconds) << " s.\n\n";
  writeConfigTable(md, s);
  writeAblations(md, s);
  if (!s.peers.empty()) writePeers(md, s, run);
  if (!s.diagnosis.empty())
    md << "### Where the light goes (--diagnose)\n\n" << s.diagnosis << "\n";
  if (!s.configs.empty()) {
    const fs::path plot = outDir / s.name / "error-vs-time.png";
    fs::create_directories(plot.parent_path());
    writePlot(plot, s);
    md << "![" << s.name << "](" << s.name << "/error-vs-time.png)\n\n";
  }
}

// A probe pass's median GPU time (0 where the configuration did not run it), and the select and
// bounce passes as the gpu table's columns sum them.
double passMs(const std::map<std::string, double>& passes, const char* name) {
  auto it = passes.find(name);
  return it == passes.end() ? 0.0 : it->second;
}
double selectMs(const std::map<std::string, double>& p) {
  return passMs(p, "probe_select_count") + passMs(p, "probe_select_emit") +
         passMs(p, "probe_select_args");
}
double bounceMs(const std::map<std::string, double>& p) {
  return passMs(p, "probe_bounce_cells") + passMs(p, "probe_bounce_rays") +
         passMs(p, "probe_bounce_own");
}

// The gpu table's second view of each configuration: the same passes once the field has
// settled, beside the young field's probe counts and states.
void writeSettledTable(std::ostringstream& md, const SceneReport& s) {
  bool header = false;
  for (const ConfigResult& c : s.configs) {
    const ConfigResult::Settled& z = c.settled;
    if (z.afterFrames == 0) continue;
    if (!header) {
      md << "\nSettled field: each configuration run on to frame " << z.afterFrames
         << " and measured again (" << s.measuredFrames
         << " frames): what a frame costs while nothing changes, most probes asleep and "
            "refreshed on their schedule. The table above measures the young field (every live "
            "probe vigilant, the cost after a light switch or in a new area).\n\n| config | "
            "probes updated, young → settled | states off / sleeping / awake / vigilant, young "
            "→ settled | classify | select | trace | bounce cells | blend | **probe update** | "
            "sampling | rays cached |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
      header = true;
    }
    auto states = [](const std::array<std::uint32_t, 4>& k) {
      return std::to_string(k[0]) + " / " + std::to_string(k[1]) + " / " + std::to_string(k[2]) +
             " / " + std::to_string(k[3]);
    };
    md << "| " << c.config << " | " << fmt("%.0f", c.probesUpdated) << " → "
       << fmt("%.0f", z.probesUpdated) << " | " << states(c.probeStates) << " → "
       << states(z.probeStates) << " | " << fmt("%.3f", passMs(z.passMs, "probe_classify")) << " | "
       << fmt("%.3f", selectMs(z.passMs)) << " | " << fmt("%.3f", passMs(z.passMs, "probe_trace"))
       << " | " << fmt("%.3f", bounceMs(z.passMs)) << " | "
       << fmt("%.3f", passMs(z.passMs, "probe_blend")) << " | " << fmt("%.3f", z.updateMs) << " | "
       << fmt("%.3f", z.sampleMs) << " | " << fmt("%.0f", z.raysCached) << " |\n";
  }
}

}  // namespace

void writeBenchGiOutputs(const fs::path& outDir, std::vector<SceneReport>& scenes,
                         const RunInfo& run) {
  for (SceneReport& s : scenes) markPareto(s.configs);
  writeText(outDir / "results.csv", resultsCsv(scenes));
  std::ostringstream md;
  writeMethod(md, run);
  writeVerdict(md, scenes, run);
  for (const SceneReport& s : scenes) writeScene(md, s, outDir, run);
  writeText(outDir / "summary.md", md.str());
}

void writeGpuTable(const fs::path& outDir, const SceneReport& s, const RunInfo& run) {
  std::ostringstream md, csv;
  md << "# Per-pass GPU times: " << s.name << "\n\n`sdfstream " << run.command << "` on **"
     << run.device << "**. "
     << (s.rounds > 1 ? "Each configuration's fastest of " + std::to_string(s.rounds) +
                            " rounds run in turn (probe update + sampling); "
                      : std::string())
     << "Medians over " << s.measuredFrames << " frames after " << s.warmupFrames
     << " warm-up frames, from the passes' GPU timestamps. Sampling: `probe_sample` for the "
     << s.points << " visible points of one " << s.width << "×" << s.height
     << " view. Light cache: relighting every resident page (the first frame's, then the median of "
        "five forced relights once settled).\n\n"
     << "SDFDDGI's Sponza grid is 22×14×32 = 9,856 probes; our probe grids are 17³ per cascade "
        "at one probe per brick (9³ / 5³ at 2 / 4 bricks), so the nearest count we can run is "
        "2 cascades × 17³ = 9,826 probes (within 0.3%). Our default uses "
     << (s.configs.size() > 1 ? std::to_string(s.configs[1].cascades) : "?") << " cascades.\n\n"
     << "| config | probes | rays/probe | classify | select | trace | bounce cells | blend "
        "| **probe update** | **sampling** | ns/query | **light cache** (full relight, first "
        "frame) "
        "| relight, warm median of 5 | probes updated | "
        "rays traced | rays cached | fresh G rays/s | MiB "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  csv << "scene,config,probes,rays,classify_ms,select_ms,trace_ms,bounce_ms,blend_ms,"
         "update_ms,"
         "sample_ms,sample_ns_per_query,light_relight_ms,light_relight_warm_ms,probes_updated,"
         "rays_traced,rays_cached,fresh_grays_per_s,memory_mib,settled_after_frames,"
         "settled_update_ms,settled_sample_ms,settled_probes_updated\n";
  for (const ConfigResult& c : s.configs) {
    auto pass = [&](const char* n) { return passMs(c.passMs, n); };
    const double select = selectMs(c.passMs);
    const double bounce = bounceMs(c.passMs);
    // Fresh rays per second of the trace pass: its throughput when (nearly) every ray is traced
    // afresh (plain DDGI); with the hit cache it mostly measures shading, not traversal.
    const double freshRate =
        pass("probe_trace") > 0.0 ? c.raysTraced / (pass("probe_trace") * 1e-3) * 1e-9 : 0.0;
    md << "| " << c.config << " | " << c.probes << " | " << c.rays << " | "
       << fmt("%.3f", pass("probe_classify")) << " | " << fmt("%.3f", select) << " | "
       << fmt("%.3f", pass("probe_trace")) << " | " << fmt("%.3f", bounce) << " | "
       << fmt("%.3f", pass("probe_blend")) << " | " << fmt("%.3f", c.updateMs) << " | "
       << fmt("%.3f", c.sampleMs) << " | " << fmt("%.2f", c.sampleNsPerQuery) << " | "
       << fmt("%.3f", c.lightRelightMs) << " | " << fmt("%.3f", c.lightRelightWarmMs) << " | "
       << fmt("%.0f", c.probesUpdated) << " | " << fmt("%.0f", c.raysTraced) << " | "
       << fmt("%.0f", c.raysCached) << " | " << fmt("%.3f", freshRate) << " | "
       << fmt("%.1f", c.memoryMiB()) << " |\n";
    csv << s.name << ',' << c.config << ',' << c.probes << ',' << c.rays << ','
        << pass("probe_classify") << ',' << select << ',' << pass("probe_trace") << ',' << bounce
        << ',' << pass("probe_blend") << ',' << c.updateMs << ',' << c.sampleMs << ','
        << c.sampleNsPerQuery << ',' << c.lightRelightMs << ',' << c.lightRelightWarmMs << ','
        << c.probesUpdated << ',' << c.raysTraced << ',' << c.raysCached << ',' << freshRate << ','
        << c.memoryMiB() << ',' << c.settled.afterFrames << ',' << c.settled.updateMs << ','
        << c.settled.sampleMs << ',' << c.settled.probesUpdated << '\n';
  }
  writeSettledTable(md, s);
  md << "\nLight cache under a sun that moves every frame (time of day): a new light every "
        "frame, at most the budget's pages relit per frame (LightRelightQueue: the longest out "
        "of date first), median over 16 frames after 64; staleness = the most frames any "
        "resident page showed old light.\n\n| config | resident pages | budget (pages/frame) | "
        "**light cache ms/frame** | full relight, warm | staleness (frames) |\n"
        "|---|---|---|---|---|---|\n";
  for (const ConfigResult& c : s.configs)
    for (const ConfigResult::MovingSun& m : c.movingSun)
      md << "| " << c.config << " | " << m.residentPages << " | " << m.budget << " | "
         << fmt("%.3f", m.lightMs) << " | " << fmt("%.3f", c.lightRelightWarmMs) << " | "
         << m.stalenessFrames << " |\n";
  bool workHeader = false;
  for (const ConfigResult& c : s.configs) {
    const LightCacheWork& w = c.lightWork;
    if (w.pages == 0) continue;
    if (!workHeader) {
      md << "\nThe full relight's work (CPU reference, same math): surface cells, their shadow "
            "rays and sphere-tracing steps; warp-steps = Σ over warps of 32 lanes of the longest "
            "lane's steps, with the cells handed out as the pass does (per page, 64 lanes), as "
            "one list over all pages, and the floor (steps / 32); lane use = floor / warp-steps."
            "\n\n| config | pages | surface cells | shadow rays (blocked) | steps / surface cell "
            "(median, p99, max) | steps by page cascade (cells) | warp-steps: per page / one "
            "list / floor | lane use: per page / one list |\n|---|---|---|---|---|---|---|---|\n";
      workHeader = true;
    }
    std::string byCascade;
    for (std::size_t k = 0; k < w.stepsByCascade.size(); ++k)
      byCascade += (k ? ", " : "") + std::to_string(k) + ": " +
                   fmt("%.1f", w.surfaceCellsByCascade[k] ? double(w.stepsByCascade[k]) /
                                                                double(w.surfaceCellsByCascade[k])
                                                          : 0.0) +
                   " (" + std::to_string(w.surfaceCellsByCascade[k]) + ")";
    auto use = [&](std::uint64_t warpSteps) {
      return fmt("%.2f", warpSteps ? double(w.warpStepsFloor) / double(warpSteps) : 0.0);
    };
    md << "| " << c.config << " | " << w.pages << " | " << w.surfaceCells << " | " << w.shadowRays
       << " (" << w.blockedRays << ") | "
       << fmt("%.1f", w.surfaceCells ? double(w.steps) / double(w.surfaceCells) : 0.0) << " ("
       << w.medianCellSteps << ", " << w.p99CellSteps << ", " << w.maxCellSteps << ") | "
       << byCascade << " | " << w.warpStepsPerPage << " / " << w.warpStepsOneList << " / "
       << w.warpStepsFloor << " | " << use(w.warpStepsPerPage) << " / " << use(w.warpStepsOneList)
       << " |\n";
  }
  const PrimaryTraceTiming& p = s.primary;
  if (p.rays > 0)
    md << "\nPrimary-ray SDF traversal alone (`trace_stack`, no shading), " << s.width << "×"
       << s.height
       << " rays from the stream camera along its view direction (60° field of view): " << p.rays
       << " rays, " << p.hits << " hits, " << fmt("%.3f", p.milliseconds) << " ms = "
       << fmt("%.3f", p.milliseconds > 0.0 ? double(p.rays) / (p.milliseconds * 1e-3) * 1e-9 : 0.0)
       << " G rays/s (median of " << p.timedDispatches
       << " dispatches back to back once the GPU's clocks were up: "
       << fmt("%.3f", p.minMilliseconds) << "-" << fmt("%.3f", p.maxMilliseconds) << " ms, against "
       << fmt("%.3f", p.coldMilliseconds) << " ms for the first dispatch, after "
       << fmt("%.1f", p.warmupSeconds) << " s of warm-up" << (p.settled ? "" : ", not settled")
       << "). Steps per ray " << fmt("%.1f", p.meanSteps) << " (99th percentile "
       << fmt("%.0f", p.p99Steps) << "); the longest ray's steps in its group of 32, per ray: "
       << fmt("%.1f", p.groupStepsRows) << " in rows as dispatched, "
       << fmt("%.1f", p.groupStepsTiles) << " in 8×4 tiles. Steps per ray by kind (CPU reference, "
       << (p.cpuStepsEqual ? "the same steps as the GPU's ray for ray"
                           : "**steps differ from the GPU's**")
       << "): " << fmt("%.1f", p.stepsByKind[0]) << " within a voxel of a surface, "
       << fmt("%.1f", p.stepsByKind[1]) << " farther inside the band, "
       << fmt("%.1f", p.stepsByKind[2]) << " clamped at the band's edge, "
       << fmt("%.1f", p.stepsByKind[3]) << " leaps across empty pages, "
       << fmt("%.1f", p.stepsByKind[4]) << " at missing pages.\n";
  writeText(outDir / ("gpu-table-" + s.name + ".md"), md.str());
  writeText(outDir / ("gpu-table-" + s.name + ".csv"), csv.str());
  std::fputs(md.str().c_str(), stdout);
}

}  // namespace sdfstream::bench
