// Settings of the probe field (one DDGI volume per SDF cascade) and the per-frame constants both
// its GPU passes (gi/probe_field.h) and its CPU reference (gi/probe_field_cpu.h) run on: this
// file is where scrolling is decided (each volume's grid follows its cascade window in whole
// probe spacings, stored toroidally), which hit-cache rotation a frame uses, and which pages
// changed since the previous frame.
//
// Units: cascade-0 voxels relative to cascade 0's minimum corner (CascadeStackImage::toStack).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/light_layout.h"
#include "shaders/shared/probe_layout.h"
#include "streaming/cascade_stack.h"

namespace sdfstream::probe {

// Probe rays per frame, all cascades, on a real GPU. On the H200 (Sponza, 19,652 probes) half of
// 2^21 kept the error after 32 frames (relMSE 0.185 against 0.187) and cost two more frames after
// a light switch (7 against 5), for 1.50 ms of probe update in the vigilant frames against 2.09
// (DECISIONS, "The probe ray budget").
inline constexpr std::uint32_t kDefaultProbeRayBudget = 1u << 20;

// Hit-cache rotation slots a probe can step through (its history keeps the slot in 4 bits).
inline constexpr std::uint32_t kMaxCacheRotations = 16;

struct ProbeFieldSettings {
  std::uint32_t spacingBricks = 1;  // probe spacing in bricks of its cascade: 1, 2 or 4 (grid
                                    // 17³, 9³ or 5³ per cascade; SDFGI slides: 17³ per 128³)
  std::uint32_t raysPerProbe = gpu_shared::kProbeDefaultRays;
  float irradianceHysteresis = gpu_shared::kProbeDefaultHysteresis;
  float depthHysteresis = gpu_shared::kProbeDefaultHysteresis;
  float vigilantHysteresis = 0.3f;  // new probes and probes after a light change (M21 Sec. 5)
  // Frames a probe stays vigilant when it is new (first frame, scrolled in) or the lights
  // changed: the multi-bounce builds up over tens of frames at 0.97 in a bright interior
  // (Breakfast Room E/E_ref after 32 + 6 frames: 0.765 at 8, 0.930 at 32; docs/DECISIONS.md).
  std::uint32_t vigilantFrames = 32;
  // ... and when a moving object passes near it: short, since low hysteresis is visible as
  // flicker where objects keep moving. Both at most 255.
  std::uint32_t objectVigilantFrames = 8;
  // ... and after a light switch: updates, not frames (GiSettings::lightSwitchCatchUpFrames runs
  // three a frame, so the default vigilance ends with its 6 frames). Short, because a vigilant
  // update holds mostly its own rotation's 128 directions, each with its own bias against the
  // converged field: the field leaves that plateau only when the vigilance ends, with the mean
  // below. 0: vigilantFrames.
  std::uint32_t lightSwitchVigilantUpdates = 18;
  // Vigilant hysteresis in the frames of GiSystem's light-switch catch-up: 0 takes each update's
  // fresh estimate whole. An interior lit mostly by bounces gains one bounce per update, and the
  // light still missing shrinks by h + (1 - h) rho an update (rho: the share of the light that
  // comes back by a bounce, ~0.8 in the Breakfast Room): 0.86 at 0.3, 0.8 at 0. The noise of
  // one rotation's rays that this leaves is what the closing mean (vigilantMeanUpdates) averages.
  float lightSwitchHysteresis = 0.0f;
  // The last this many updates of a light switch's vigilance take a running mean (hysteresis
  // 1/2, 2/3, ...) instead of vigilantHysteresis: over as many hit-cache rotations they weigh
  // every rotation's directions alike, so the field the vigilance leaves behind is the
  // rotations' mean, which the calm 0.97 then only refines. A new probe's vigilance keeps
  // vigilantHysteresis to its end: its bounces may still be building up then, and the mean's
  // slower blend would hold them back. 0: off. At most 255.
  std::uint32_t vigilantMeanUpdates = 4;
  bool adaptiveHysteresis = true;              // per-texel change heuristic (M21 Sec. 4.3)
  float maxDepthSpacings = 2.0f * 1.7320508f;  // depth a miss records, in probe spacings
  // Exponent of the irradiance encoding the blend works in (texel = E^(1/gamma)). 1: linear.
  // M21 Sec. 4.2 blends E^(1/5) (kProbeIrradianceGamma) to spend an 8-10-bit texel's precision on
  // the darks; our texels are fp32, so the encoding buys nothing and costs light: the blended
  // history is then the mean of fifth roots, below the mean wherever a few rays bring most of
  // the light (Breakfast Room E/E_ref 0.690 -> 0.754 linear, docs/DECISIONS.md).
  float irradianceGamma = 1.0f;
  float depthSharpness = gpu_shared::kProbeDepthSharpness;
  float selfShadowBias = gpu_shared::kProbeDefaultSelfShadowBias;
  float backfaceDepthScale = gpu_shared::kProbeBackfaceDepthScale;
  // A ray that hits a backface (the probe sees the inside of geometry) is left out of the
  // irradiance blend (RTXGI's rule: it carries no light; counted as black it darkens probes whose
  // rays graze thin or coarse geometry -- 0.1-0.3% of the rays in the bench scenes); it still
  // shortens the depth moments and counts towards "inside". True blends it as black radiance
  // instead (the first rule; for comparison).
  bool backfacesBlack = false;
  float minVariance = gpu_shared::kProbeMinVariance;
  float bounceGain = 1.0f;  // multi-bounce feedback
  // Updates a bounce cell's lookup of the probes serves the hits in its material voxel
  // (probe_trace.glsl, "Bounce cells"): a hit reads the cell's irradiance instead of weighing 8
  // probes (16 in a cascade blend) itself. Four times the hit cache's 4 rotations: a cell that
  // only one rotation's rays hit is hit every 4th update, and with 4 it was looked up at every
  // hit (Sponza on the H100, steady probe update: 0.765 ms at 4, 0.682 at 8, 0.648 at 16, with
  // the full-mode accuracy of 8 to the third digit in five scenes). 1: each cell is looked up
  // afresh every update (once for all its hits), which the field's young updates and a light
  // switch's vigilance use, since their bounces build up one per update; while the lights drift
  // a cell serves half as many. 0: every hit looks the probes up itself.
  std::uint32_t bounceCellUpdates = 16;
  // The near-field gather when sampling (shaders/probe_near_field.glsl): rays per receiver
  // (0: off, sampling reads the probe cage alone; at most 255) to nearFieldReach probe spacings
  // of the receiver's cascade (eighths, up to 31.875).
  std::uint32_t nearFieldRays = 0;
  float nearFieldReach = 1.0f;
  std::uint32_t maxSteps = 256;  // sphere-tracing iterations per ray, all cascades together
  float hitEpsilon = 0.02f;      // voxels of the cascade being traced
  float traceDistance = 1e30f;   // probe ray tMax, cascade-0 voxels
  std::uint64_t rotationSeed = 1;
  bool hitCache = true;  // GS "Caching rays"
  // Cycle the cache's rotation slots even with the cache off, so a test can compare cache on
  // and off on the very same rays (off by default: without a cache, a fresh rotation per frame
  // is the better estimator).
  bool fixedRotationCycle = false;
  // Ray rotations a probe steps through, one per update, when the cache is on (memory: probes x
  // rays x rotations x 8 bytes; at most kMaxCacheRotations).
  std::uint32_t cacheRotations = 4;
  bool states = true;                // M21 Sec. 5 probe states
  std::uint32_t sleepPeriod = 8;     // sleeping probes refresh every this many frames
  // A light change this small is a drift, not a wake (GiSystem): every sun turns by at most
  // this many degrees since the last frame, and every light's and the sky's colour x intensity
  // changes by at most lightDriftIntensity of it, with nothing else changed. A drift wakes no
  // probe (a sun that moves a fraction of a degree a frame woke the whole field every frame:
  // ~6 ms on the H200, docs/GPU_BUDGET.md); sleeping probes follow it at their refreshes. 0: every
  // light change wakes the field.
  float lightDriftDegrees = 1.0f;
  float lightDriftIntensity = 0.05f;
  float sleepThreshold = 0.05f;        // an update is "quiet" when its fresh estimate of the mean
                                       // irradiance is within this of the stored one
  bool relocation = true;              // SDFDDGI Sec. 4.1
  // Fraction of the spacing kept free between a probe and the static surfaces (moving objects:
  // kProbeObjectClearance). 0.15 with the crush at 0.05 (docs/DECISIONS.md, "Clearance 0.15,
  // crush 0.05").
  float relocationMinDistance = 0.15f;
  enum class Visibility { Chebyshev, Sdf, ChebyshevAndSdf };
  Visibility visibility = Visibility::ChebyshevAndSdf;  // sampling's visibility test
  // With ChebyshevAndSdf: trace the SDF only for the cage corners whose depth moments leave the
  // answer open (probe_sample.glsl, probeSdfVisibilityPresumed); false traces every corner.
  bool sdfVisibilityWhereUnsure = true;
  // probe_sample.comp (ProbeField::sample, GiSystem::irradiance): kProbeSampleShareLanes
  // neighbouring queries in one cage split its SDF tests (probeGroupSharesCage); false: each
  // traces its own, the answers of a per-pixel shader (sdfstream/probe_sample.glsl) bit for bit.
  bool shareSdfTests = true;
  std::uint32_t rayBudget = kDefaultProbeRayBudget;  // rays per frame (all cascades)
  float viewConeDegrees = 60.0f;                     // half-angle of the cone counted as "in view"

  glm::uvec3 grid() const { return glm::uvec3(16u / spacingBricks + 1u); }
  std::uint32_t probesPerVolume() const {
    const glm::uvec3 g = grid();
    return g.x * g.y * g.z;
  }
  // Probes per frame the ray budget allows (at most every probe of `cascades` volumes).
  std::uint32_t listCapacity(std::uint32_t cascades) const;
  // A light switch's vigilance where every probe fits a list: lightSwitchVigilantUpdates, or
  // vigilantFrames when that is 0.
  std::uint32_t switchVigilantUpdates() const {
    return lightSwitchVigilantUpdates > 0 ? lightSwitchVigilantUpdates : vigilantFrames;
  }
};

// What the caller knows about a frame besides the stack.
// Whether frame f checks the hit cache (probeCacheCheckPass): the cache is on and a window
// scrolled or pages changed (kProbeOptionCacheCheck); the GPU and CPU fields dispatch the pass
// only then.
inline bool checksHitCache(const gpu_shared::ProbeFrame& f) {
  return (f.options.x & gpu_shared::kProbeOptionHitCache) != 0u &&
         (f.options.x & gpu_shared::kProbeOptionCacheCheck) != 0u;
}

struct ProbeFrameInputs {
  glm::dvec3 cameraWorld{0.0};
  glm::vec3 viewDirection{0.0f, 0.0f, -1.0f};
  gpu_shared::GpuSky sky{};
  bool lightsChanged = false;  // wakes every probe (vigilant) for vigilantFrames
  // The lights changed a little (GiSystem decides, ProbeFieldSettings::lightDriftDegrees): no
  // probe wakes; sleeping probes keep their period and their refresh follows the light.
  // lightsChanged wins when both are set.
  bool lightsDrifting = false;
  // No probe passes this frame: the field keeps what it holds (a host's "GI off" that saves the
  // probes' GPU time; the light cache, objects and streaming still update). Unpaused, the field
  // catches up from where it stood, as after a camera jump.
  bool paused = false;
  // Added to the frame number wherever an update picks by it -- the select pass's schedule and
  // its share of an overflowing class, and without the hit cache the fresh rotation: a second
  // update in the same frame (GiSystem's light-switch catch-up) takes other probes where not all
  // fit. (With the cache each probe steps through the rotations by itself.)
  std::uint32_t updateShift = 0;
  // With lightsChanged: the switch's vigilance in updates (0: lightSwitchVigilantUpdates).
  std::uint32_t lightSwitchVigilantUpdates = 0;
  // A frame of GiSystem's catch-up after a light switch: vigilant probes blend with
  // ProbeFieldSettings::lightSwitchHysteresis instead of vigilantHysteresis.
  bool lightSwitchCatchUp = false;
};

// Everything the passes read for one frame.
struct ProbeFieldFrame {
  gpu_shared::ProbeFrame constants{};
  std::vector<gpu_shared::ProbeVolume> volumes;
  std::vector<std::uint32_t> pageChanged;  // cascades x 128 words: bit i = entry i changed
  // The ray pattern: cacheRotations x 3 rotation columns, then each slot's depth texels' ray
  // lists (probe_layout.h, kProbeDepthList*). With the hit cache every frame shares one pattern
  // (the same pointer: ProbeField uploads it once); without it one fresh rotation a frame.
  std::shared_ptr<const std::vector<glm::vec4>> rayPattern;
};

// Builds successive frames; remembers the previous frame's windows and page tables.
class ProbeFieldFrameBuilder {
 public:
  explicit ProbeFieldFrameBuilder(const ProbeFieldSettings& settings);
  ProbeFieldFrame build(const CascadeStackImage& stack, const ProbeFrameInputs& in,
                        std::uint64_t frame);
  void reset();  // next frame resets every probe

 private:
  ProbeFieldSettings settings_;
  bool first_ = true;
  std::vector<glm::ivec3> gridOrigins_;    // per cascade, in probe spacings (world-absolute)
  std::vector<glm::dvec3> windowWorld_;    // per cascade, min corner in metres
  std::vector<std::uint32_t> pageTables_;  // previous frame
  bool driftedBefore_ = false;             // the previous frame had kProbeOptionLightsDrifting
  std::uint32_t updates_ = 0;        // frames built (the bounce cells' stamps; never restarts)
  std::uint32_t buildingUntil_ = 0;  // the bounces build up until here (new field, light switch)
  std::shared_ptr<const std::vector<glm::vec4>> pattern_;  // the cache's pattern (built once)
};

}  // namespace sdfstream::probe
