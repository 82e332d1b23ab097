// The run of one `bench gi` configuration (bench/bench_gi_run.h: runConfig), shared by its two
// halves: bench_gi_run.cpp (warm-up, measurement, the peers, the light switch) and
// bench_gi_run_diagnose.cpp and
// bench_gi_run_near_field.cpp (--diagnose: where the light goes). Internal to bench/.
#pragma once

#include <cstdint>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "bench/bench_gi_peers.h"
#include "bench/bench_gi_run.h"
#include "gi/gi_system.h"
#include "gi/probe_field_frame.h"
#include "reference/embree_scene.h"

namespace sdfstream::bench {

// A probe at its relocated position (cascade-0 voxels), with its cascade and logical grid index.
struct LiveProbe {
  glm::vec3 stack;
  std::uint32_t cascade, cell;
};

// Global probe g (cascade * perVolume + storage index) of frame f, its data d (offset, state).
LiveProbe probeAt(const probe::ProbeFieldFrame& f, std::uint32_t perVolume, std::uint32_t g,
                  glm::vec4 d);

// Every probe of `gi` that is not off.
std::vector<LiveProbe> liveProbes(const GiSystem& gi, const probe::ProbeFieldFrame& f,
                                  std::uint32_t perVolume);

// The probes of the receivers' cages (the 8 grid corners around each query in the cascade it is
// sampled from), as cascade * perVolume + logical cell.
std::set<std::uint32_t> cageProbes(const probe::ProbeFieldFrame& f, std::uint32_t perVolume,
                                   std::span<const gpu_shared::ProbeQuery> queries);

// Where a ray from o along unit dir leaves the box [lo, hi] (o inside; 0 when it starts outside).
float boxExit(glm::vec3 lo, glm::vec3 hi, glm::vec3 o, glm::vec3 dir);

// Probe rays of one frame of `gi` (every probe that is not off, raysPerProbe rays each, this
// frame's rotation), in both frames, bounded by the coarsest cascade's window.
PeerRays probeRaySet(const GiSystem& gi, const CascadeStackImage& img,
                     const probe::ProbeFieldSettings& s, const probe::ProbeFrameInputs& in,
                     std::uint64_t frame);

// A fresh GiSystem for one configuration on the scene's stack of its cascade count, and the
// frames it runs.
class ConfigRun {
 public:
  ConfigRun(SceneContext& sc, const GiConfig& cfg)
      : sc_(sc),
        cfg_(cfg),
        st_(sc.stacks.at(cfg.cascades)),
        gi_(sc.ctx, settings(cfg), std::uint32_t(cfg.cascades)) {
    in_.cameraWorld = sc.scene.streamCamera;
    in_.viewDirection = sc.scene.viewDirection;
    lights_ = sc.scene.lights;
    lights_.version = 0;
  }

  // One GI frame; the first uploads every atlas slot.
  GiFrameStats step() {
    const std::span<const std::uint32_t> dirty = frame_ == 0
                                                     ? std::span<const std::uint32_t>(st_.allSlots)
                                                     : std::span<const std::uint32_t>();
    return gi_.update(*st_.stack, dirty, lights_, in_, frame_++);
  }

  std::uint64_t frame() const { return frame_; }

  // Relights every resident page `repeats` times (a new light version each frame) after the
  // run has settled: the median light-cache time of a warm full relight. The first frame's
  // relight also pays the first upload's cold caches.
  double measureRelightMs(int repeats);
  // What relighting every resident page under the current lights asks of the light cache pass
  // (counted on the CPU).
  LightCacheWork lightWork() const;

  // A sun that moves every frame, with the light cache's relight budget of `pageBudget` pages per
  // frame (fly's default on a GPU): `warmup` frames to reach the steady state, then the median
  // light-cache time, the largest staleness and the resident pages of `frames` frames into r.
  // The budget returns to every page afterwards.
  void measureMovingSun(std::uint32_t pageBudget, int warmup, int frames, ConfigResult& r);

  // The measured frames: medians of the pass times and work, and device memory, into r. Returns
  // the last frame's irradiance at every point.
  std::vector<glm::vec3> measure(ConfigResult& r);

  // What the peers and the ray diagnosis share: this run's stack, the scene, the traversal's
  // settings.
  PeerInputs peerInputs(const EmbreeScene& embree) const {
    PeerInputs pi;
    pi.context = &sc_.ctx;
    pi.stack = st_.stack.get();
    pi.allSlots = st_.allSlots;
    pi.triangles = sc_.scene.triangles.get();
    pi.embree = &embree;
    pi.voxelSize = sc_.scene.voxelSize;
    pi.maxSteps = cfg_.probes.maxSteps;
    pi.hitEpsilon = cfg_.probes.hitEpsilon;
    return pi;
  }

  // The reference irradiance (NoDirectLights, cached with the scene's) at world points; paths
  // of at most maxDepth surface hits (1: one bounce, as a bounceGain-0 field holds).
  std::vector<glm::vec3> referenceAt(std::span<const glm::vec3> positions,
                                     std::span<const glm::vec3> normals,
                                     std::uint32_t maxDepth = 64) const;

  // This frame's probe volumes as the passes see them (grids, spacings, scroll).
  probe::ProbeFieldFrame frameConstants(const CascadeStackImage& img) const {
    probe::ProbeFieldFrameBuilder builder(cfg_.probes);
    return builder.build(img, in_, frame_);
  }

  // The traversal peers on this frame's probe rays.
  void runPeersOnProbeRays(SceneReport& into);

  // --diagnose: this frame's probe rays against Embree, by the cascade they end in.
  void diagnoseRays(SceneReport& into);

  // --diagnose, on the one-bounce run (bounceGain 0): what each probe ray of one frame brought
  // back against what the same ray brings back on the triangles: the sky where Embree's ray
  // escapes the scene (unbounded: what lies beyond the stack is part of what our rays miss),
  // else emission + albedo/pi x the delta lights (hard shadows) at Embree's hit -- the same
  // one-bounce transport. Mean luminance over every ray and
  // over the rays of the receivers' cage probes, split by what both saw.
  void diagnoseRayRadiance(SceneReport& into);

  // --diagnose: the receivers moved off their surface along the normal by one probe spacing of
  // their sampling cascade (in free space, up to 4096 of them), GI against the reference there.
  // Near the probes-themselves ratio while the receivers' is not: the loss is in sampling next
  // to surfaces; as low as the receivers': it is regional, in what the nearby probes gather.
  void diagnoseAwayFromSurfaces(SceneReport& into, bool oneBounce);

  // --diagnose: what a near-field gather from the receivers would read (an oracle on the
  // triangles, no GPU code behind it): per receiver (up to 512) K cosine-distributed rays traced
  // by Embree to R; a hit within R brings its emission + albedo/pi x (its delta lights + the
  // irradiance there: our field's, or the reference's), a miss the field's irradiance at the
  // ray's end with the ray's direction for normal, over pi (ours, or the reference's). Against
  // the GI's own sampling of the same receivers, for R of 0.5, 1 and 2 probe spacings.
  void diagnoseNearField(SceneReport& into);
  std::string nearFieldApart(const CascadeStackImage& img, const probe::ProbeFieldFrame& f,
                             std::span<const std::uint32_t> picks,
                             std::span<const std::size_t> receivers,
                             std::span<const glm::vec3> rayDir,
                             std::span<const std::uint8_t> hitKind,
                             std::span<const glm::vec3> atPos, std::span<const glm::vec3> atNrm,
                             std::span<const glm::vec3> hitAlbedo, std::span<const glm::vec3> ours,
                             std::span<const glm::vec3> ref, float spacings);

  // --diagnose: the receivers of each sampling cascade k, sampled from k alone and from each
  // coarser cascade alone: whether another cascade's probes would serve them better.
  void diagnoseCascadesAlone(SceneReport& into);

  // --diagnose: the field's irradiance at the probes themselves (up to 512 probes that are not
  // off, 6 axis normals each) against the reference there: over every probe, and over the
  // receivers' cage probes (those the receivers are sampled from; "every probe" is mostly open
  // space). Near 1 while the receivers' E/E_ref is not: the loss is in sampling (weights,
  // visibility); as low as the receivers': it is in what the probes gather.
  void diagnoseProbeIrradiance(SceneReport& into);

  // Light switch: off for offFrames, then on again. Converged = 95% of the switch's effect
  // recovered beyond the field's own jitter: mean |E_t - E_on| <= 0.05 mean |E_on - E_off| +
  // mean |E_on' - E_on| (E_on, E_on' two consecutive converged frames; E_off the last dark
  // frame; luminance at <= 1024 test points). Measured against the change, not against E: where
  // the sky dominates (outdoors) a sun switch is a few percent of E and would "converge" at once.
  void measureConvergence(ConfigResult& r);

 private:
  // One frame's probe rays with what each brought back (rec.results) and what the same ray
  // brings back on the triangles, by ray (list position x rays per probe + ray).
  struct RayComparison {
    enum Group : std::uint8_t { kSkyBoth, kLitBoth, kShadowBoth, kOursOnly, kEmbreeOnly, kGroups };
    probe::ProbeField::RayRecords rec;
    probe::ProbeFieldFrame frame;
    std::vector<glm::vec4> probeData;
    std::set<std::uint32_t> cage;  // the receivers' cage probes (cageProbes)
    std::vector<float> ours, ref;  // luminance of our radiance and the triangles'
    std::vector<std::uint8_t> group, inCage, cascadeOf;
    std::vector<float> triT;                      // Embree's hit distance (-1: none)
    std::vector<glm::vec3> triNormal, triAlbedo;  // at Embree's hit, normal facing the ray
  };
  RayComparison compareRays(const CascadeStackImage& img, const EmbreeScene& embree);
  void diagnoseSunlitHits(SceneReport& into, const RayComparison& c, const CascadeStackImage& img,
                          const EmbreeScene& embree);
  void diagnoseFrameAgainstStored(SceneReport& into, const RayComparison& c);
  void writeRayTable(SceneReport& into, const RayComparison& c);

  static GiSettings settings(const GiConfig& cfg) {
    GiSettings gs;
    gs.probes = cfg.probes;
    return gs;
  }

  SceneContext& sc_;
  const GiConfig& cfg_;
  StreamedStack& st_;
  GiSystem gi_;
  probe::ProbeFrameInputs in_;
  SceneLights lights_;
  std::uint64_t frame_ = 0;
};

}  // namespace sdfstream::bench
