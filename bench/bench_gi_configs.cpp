#include "bench/bench_gi_configs.h"

#include <string>
#include <utility>

namespace sdfstream::bench {

using probe::ProbeFieldSettings;

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

ProbeFieldSettings plainDdgi() {
  ProbeFieldSettings s;
  s.spacingBricks = 1;
  s.relocation = false;
  s.states = false;
  s.hitCache = false;
  s.visibility = ProbeFieldSettings::Visibility::Chebyshev;
  s.irradianceGamma = gpu_shared::kProbeIrradianceGamma;  // as published (M21 Sec. 4.2)
  s.vigilantFrames = 8;  // the peer as first measured (our default now stays vigilant longer)
  return s;
}

namespace {

// The default at half and twice its probe ray budget: what the vigilant frames (every live probe
// wants an update; the budget decides how many get one) cost and buy.
std::vector<GiConfig> rayBudgetConfigs(int cascades, bool converge) {
  std::vector<GiConfig> out;
  const std::uint32_t def = ProbeFieldSettings{}.rayBudget;
  for (const auto& [name, budget] :
       {std::pair{"ray-budget-half", def / 2}, std::pair{"ray-budget-double", def * 2}}) {
    ProbeFieldSettings s;
    s.rayBudget = budget;
    out.push_back(
        {name, "ours", std::to_string(budget) + " rays a frame", s, cascades, converge, "default"});
  }
  return out;
}

// The default with its bounce cells serving half and twice as many updates (probe_trace.glsl,
// "Bounce cells"): lookups saved against how stale a hit's multi-bounce term may grow.
std::vector<GiConfig> bounceCellConfigs(int cascades, bool converge) {
  std::vector<GiConfig> out;
  const std::uint32_t def = ProbeFieldSettings{}.bounceCellUpdates;
  for (std::uint32_t updates : {def / 2, def * 2}) {
    ProbeFieldSettings s;
    s.bounceCellUpdates = updates;
    out.push_back({"bounce-cells-" + std::to_string(updates), "ours",
                   "a bounce cell serves " + std::to_string(updates) + " updates", s, cascades,
                   converge, "default"});
  }
  return out;
}

constexpr const char* kHalfResolutionChange =
    "sampled at half resolution, depth/normal-aware upsample";
constexpr const char* kQuarterResolutionChange =
    "sampled at quarter resolution (one pixel per 4×4), depth/normal-aware upsample";

}  // namespace

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
  add("half-res", "ours", kHalfResolutionChange, def, cascades, false);
  out.back().sampleBlock = 2;
  add("quarter-res", "ours", kQuarterResolutionChange, def, cascades, false);
  out.back().sampleBlock = 4;
  // The near-field gather (shaders/probe_near_field.glsl): rays per receiver to one probe
  // spacing, and to half of one.
  for (std::uint32_t rays : {16u, 64u}) {
    ProbeFieldSettings s = def;
    s.nearFieldRays = rays;
    add("near-field-" + std::to_string(rays), "ours",
        "near-field gather, " + std::to_string(rays) + " rays to 1 spacing", s, cascades, false);
  }
  {
    ProbeFieldSettings s = def;
    s.nearFieldRays = 16;
    s.nearFieldReach = 0.5f;
    add("near-field-16-half", "ours", "near-field gather, 16 rays to 0.5 spacing", s, cascades,
        false);
  }
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
    if (!quick)
      // A settled probe holds the mean over its cache's rotations' fixed directions: more
      // rotations, less of each probe's frozen sampling error, more cache memory.
      for (std::uint32_t r : {8u, 16u}) {
        s = base;
        s.cacheRotations = r;
        add("cache-rotations-" + std::to_string(r), "ours",
            "hit cache of " + std::to_string(r) + " rotations", s, cascades, true);
      }
    s = base;
    s.states = false;
    add(prefix + "no-states", "ours", "states off", s, cascades, !quick);
    s = base;
    s.relocation = false;
    add(prefix + "no-relocation", "ours", "relocation off", s, cascades, !quick);
    if (!quick) {
      // Where relocation leaves a probe and where the self-shadow bias moves the receiver: both
      // trade light between scenes (docs/DECISIONS.md, "Relocation clearance and self-shadow
      // bias"), so the sweep keeps a row for each.
      for (const char* clearance : {"0.1", "0.25", "0.35"}) {
        s = def;
        s.relocationMinDistance = std::stof(clearance);
        add(std::string("clearance-") + clearance, "ours",
            std::string("relocation clearance ") + clearance + " spacing", s, cascades, true);
      }
      s = def;
      s.selfShadowBias = 0.25f;
      add("self-shadow-bias-0.25", "ours", "self-shadow bias 0.25", s, cascades, true);
    }
    s = base;
    s.visibility = ProbeFieldSettings::Visibility::Chebyshev;
    add(prefix + "vis-chebyshev", "ours", "visibility chebyshev", s, cascades, !quick);
    s.visibility = ProbeFieldSettings::Visibility::Sdf;
    add(prefix + "vis-sdf", "ours", "visibility sdf", s, cascades, !quick);
    s = base;
    s.sdfVisibilityWhereUnsure = false;
    add(prefix + "vis-sdf-everywhere", "ours", "Chebyshev + the SDF test at every cage corner", s,
        cascades, !quick);
    s = base;
    s.shareSdfTests = false;
    add(prefix + "sdf-per-query", "ours", "each query traces its own SDF tests (no sharing)", s,
        cascades, !quick);
    // M21's perceptual encoding blends irradiance^(1/5): for estimates that vary from frame to
    // frame (a few rays seeing a bright patch) that mean is far below the mean of the values.
    s = base;
    s.irradianceGamma = gpu_shared::kProbeIrradianceGamma;
    add(prefix + "gamma-5", "ours", "irradiance blended as E^(1/5) (M21)", s, cascades, !quick);
    if (!quick) {
      // How long probes stay vigilant (hysteresis 0.3) after a change or at the start (the
      // default: 32; 8 was the first default): the Breakfast Room's multi-bounce builds up over
      // hundreds of frames at 0.97.
      for (std::uint32_t frames : {8u, 16u}) {
        s = base;
        s.vigilantFrames = frames;
        add("vigilant-" + std::to_string(frames), "ours",
            "vigilant for " + std::to_string(frames) + " frames after a change", s, cascades, true);
      }
      // M21 Sec. 4.3's change heuristic resets a texel to a fresh estimate that jumps: for
      // estimates that spike (a few rays on a bright patch) spikes then outlast dips.
      s = base;
      s.adaptiveHysteresis = false;
      add("fixed-hysteresis", "ours", "adaptive hysteresis off", s, cascades, true);
      s = base;
      s.backfacesBlack = true;
      add("backfaces-black", "ours", "backface rays blended as black", s, cascades, true);
    }
    if (quick)
      for (GiConfig& c : out)
        if (c.name.starts_with(prefix) && c.name != "spacing-2") c.base = "spacing-2";
  }
  if (!quick) {
    for (GiConfig& c : rayBudgetConfigs(cascades, true)) out.push_back(std::move(c));
    for (GiConfig& c : bounceCellConfigs(cascades, true)) out.push_back(std::move(c));
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

std::vector<GiConfig> gpuTableConfigs(const BenchScene& scene) {
  // SDFDDGI's Sponza grid is 22 x 14 x 32 = 9,856 probes; our grids are 17³ per cascade at one
  // probe per brick, so 2 cascades (9,826 probes) is the nearest count we can run.
  const ProbeFieldSettings def;
  ProbeFieldSettings everywhere = def;
  everywhere.sdfVisibilityWhereUnsure = false;
  ProbeFieldSettings perQuery = def;
  perQuery.shareSdfTests = false;
  std::vector<GiConfig> out = {
      {"sdfddgi-probe-count", "ours", "2 cascades x 17³ = 9,826 probes", def, 2, false, "default"},
      {"default", "ours", "", def, scene.defaultCascades, false, ""},
      {"vis-sdf-everywhere", "ours", "the SDF test at every cage corner", everywhere,
       scene.defaultCascades, false, "default"},
      {"sdf-per-query", "ours", "each query traces its own SDF tests (no sharing)", perQuery,
       scene.defaultCascades, false, "default"},
      {"plain-ddgi", "plain-ddgi", "", plainDdgi(), scene.defaultCascades, false, ""},
      {"half-res", "ours", kHalfResolutionChange, def, scene.defaultCascades, false, "default", 2},
      {"quarter-res", "ours", kQuarterResolutionChange, def, scene.defaultCascades, false,
       "default", 4}};
  for (GiConfig& c : rayBudgetConfigs(scene.defaultCascades, false)) out.push_back(std::move(c));
  for (GiConfig& c : bounceCellConfigs(scene.defaultCascades, false)) out.push_back(std::move(c));
  // The near-field gather's cost, at full and half resolution.
  for (const bool half : {false, true}) {
    ProbeFieldSettings s = def;
    s.nearFieldRays = 16;
    out.push_back(
        {half ? "near-field-16-half-res" : "near-field-16", "ours",
         std::string("near-field gather, 16 rays to 1 spacing") + (half ? ", half resolution" : ""),
         s, scene.defaultCascades, false, "default", half ? 2u : 1u});
  }
  return out;
}

}  // namespace sdfstream::bench
