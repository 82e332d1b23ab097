#include "gi/probe_field_frame.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "gi/probe_depth_lists.h"
#include "gi/probe_math.h"

namespace sdfstream::probe {
namespace {
int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
int floorMod(int a, int b) { return a - floorDiv(a, b) * b; }
}  // namespace

std::uint32_t ProbeFieldSettings::listCapacity(std::uint32_t cascades) const {
  return std::min(cascades * probesPerVolume(),
                  std::max(1u, rayBudget / std::max(1u, raysPerProbe)));
}

ProbeFieldFrameBuilder::ProbeFieldFrameBuilder(const ProbeFieldSettings& settings)
    : settings_(settings) {
  assert(settings.spacingBricks == 1 || settings.spacingBricks == 2 || settings.spacingBricks == 4);
}

void ProbeFieldFrameBuilder::reset() { first_ = true; }

ProbeFieldFrame ProbeFieldFrameBuilder::build(const CascadeStackImage& stack,
                                              const ProbeFrameInputs& in, std::uint64_t frame) {
  const ProbeFieldSettings& s = settings_;
  const std::uint32_t cascades = std::uint32_t(stack.params.size());
  const glm::uvec3 n = s.grid();
  if (gridOrigins_.size() != cascades) first_ = true;
  ProbeFieldFrame out;
  bool anyMoved = false;

  // Hit-cache rotations: a fixed set, so a ray index of a rotation slot always has the same
  // direction and its cached hit stays meaningful; each probe steps through the slots one
  // update at a time (probeHistoryListed). Their depth texels' ray lists follow, a set per slot;
  // the pattern never changes, so it is built once. Without the cache: one fresh rotation a
  // frame, in slot 0.
  const bool cycle = s.hitCache || s.fixedRotationCycle;
  const std::uint32_t slots = cycle ? std::clamp(s.cacheRotations, 1u, kMaxCacheRotations) : 1u;
  const std::uint64_t mix = s.rotationSeed * 0x9E3779B97F4A7C15ull;
  const std::uint64_t selectionFrame = frame + in.updateShift;
  if (cycle) {
    if (!pattern_) {
      auto pattern = std::make_shared<std::vector<glm::vec4>>();
      for (std::uint32_t r = 0; r < slots; ++r) {
        const glm::mat3 m = randomRotation(mix + r);
        for (int k = 0; k < 3; ++k) pattern->push_back(glm::vec4(m[k], 0.0f));
      }
      for (std::uint32_t r = 0; r < slots; ++r)
        appendDepthRayLists(randomRotation(mix + r), s.raysPerProbe, s.depthSharpness, *pattern);
      pattern_ = std::move(pattern);
    }
    out.rayPattern = pattern_;
  } else {
    auto pattern = std::make_shared<std::vector<glm::vec4>>();
    const glm::mat3 m = randomRotation(mix + 1000003u + selectionFrame);
    for (int k = 0; k < 3; ++k) pattern->push_back(glm::vec4(m[k], 0.0f));
    appendDepthRayLists(m, s.raysPerProbe, s.depthSharpness, *pattern);
    out.rayPattern = std::move(pattern);
  }

  std::vector<glm::ivec3> gridOrigins(cascades);
  std::vector<glm::dvec3> windowWorld(cascades);
  for (std::uint32_t c = 0; c < cascades; ++c) {
    const gpu_shared::CascadeTraceParams& p = stack.params[c];
    const float scale = p.offsetScale.w;
    const glm::ivec3 originBrick =
        c < stack.originBricks.size() ? stack.originBricks[c] : glm::ivec3(0);
    const int sb = int(s.spacingBricks);
    const glm::ivec3 grid(floorDiv(originBrick.x, sb), floorDiv(originBrick.y, sb),
                          floorDiv(originBrick.z, sb));
    gridOrigins[c] = grid;
    const glm::vec3 window(p.offsetScale);
    windowWorld[c] = stack.cascade0MinWorld + glm::dvec3(window) * stack.voxelSize0;
    const float spacing = 8.0f * float(sb) * scale;

    gpu_shared::ProbeVolume v{};
    v.originSpacing =
        glm::vec4(window + glm::vec3(grid * sb - originBrick) * (8.0f * scale), spacing);
    v.countsRays = glm::uvec4(n, s.raysPerProbe);
    v.scroll = glm::ivec4(floorMod(grid.x, int(n.x)), floorMod(grid.y, int(n.y)),
                          floorMod(grid.z, int(n.z)), int(c));
    glm::ivec3 moved(0);
    int reset = first_ ? 1 : 0;
    if (!first_) {
      moved = grid - gridOrigins_[c];
      if (glm::any(glm::greaterThanEqual(glm::abs(moved), glm::ivec3(n)))) reset = 1;
    }
    v.moved = glm::ivec4(moved, reset);
    v.blend = glm::vec4(s.irradianceHysteresis, s.depthHysteresis, s.maxDepthSpacings * spacing,
                        s.irradianceGamma);
    v.visibility =
        glm::vec4(s.selfShadowBias, s.depthSharpness, s.backfaceDepthScale, s.minVariance);
    const glm::dvec3 prev = first_ ? windowWorld[c] : windowWorld_[c];
    const glm::vec3 prevWindow((prev - stack.cascade0MinWorld) / stack.voxelSize0);
    v.prevWindow = glm::vec4(prevWindow, 128.0f * scale);
    if (prevWindow != window) anyMoved = true;
    out.volumes.push_back(v);
  }

  out.pageChanged.assign(std::size_t(cascades) * 128, 0u);
  bool anyPageChanged = false;
  for (std::size_t i = 0; i < stack.pageTables.size(); ++i)
    if (first_ || pageTables_.size() != stack.pageTables.size() ||
        pageTables_[i] != stack.pageTables[i]) {
      out.pageChanged[i >> 5] |= 1u << (i & 31u);
      anyPageChanged = true;
    }

  gpu_shared::ProbeFrame& f = out.constants;
  f.skyZenith = glm::vec4(glm::vec3(in.sky.zenith), s.bounceGain);
  f.skyHorizon = glm::vec4(glm::vec3(in.sky.horizon), float(stack.voxelSize0));
  const float cosCone = std::cos(s.viewConeDegrees * 3.14159265f / 180.0f);
  f.camera = glm::vec4(stack.toStack(in.cameraWorld), cosCone);
  const float len = glm::length(in.viewDirection);
  f.view =
      glm::vec4(len > 0.0f ? in.viewDirection / len : glm::vec3(0, 0, -1),
                     in.lightSwitchCatchUp ? s.lightSwitchHysteresis : s.vigilantHysteresis);
  f.counts = glm::uvec4(cascades, s.probesPerVolume(), 0u, s.rayBudget);
  std::uint32_t options = 0;
  if (s.hitCache) options |= gpu_shared::kProbeOptionHitCache;
  if (s.states) options |= gpu_shared::kProbeOptionStates;
  if (s.relocation) options |= gpu_shared::kProbeOptionRelocation;
  if (s.visibility != ProbeFieldSettings::Visibility::Chebyshev)
    options |= gpu_shared::kProbeOptionSdfVisibility;
  if (s.visibility == ProbeFieldSettings::Visibility::Sdf)
    options |= gpu_shared::kProbeOptionNoChebyshev;
  if (!s.sdfVisibilityWhereUnsure) options |= gpu_shared::kProbeOptionSdfEverywhere;
  if (!s.shareSdfTests) options |= gpu_shared::kProbeOptionSdfPerQuery;
  if (in.lightsChanged) options |= gpu_shared::kProbeOptionLightsChanged;
  const bool drifting = in.lightsDrifting && !in.lightsChanged && !first_;
  if (drifting) options |= gpu_shared::kProbeOptionLightsDrifting;
  if (driftedBefore_) options |= gpu_shared::kProbeOptionDriftedBefore;
  if (s.adaptiveHysteresis) options |= gpu_shared::kProbeOptionAdaptiveHysteresis;
  if (s.backfacesBlack) options |= gpu_shared::kProbeOptionBackfacesBlack;
  if (first_) options |= gpu_shared::kProbeOptionFirstFrame;
  if (anyMoved || anyPageChanged) options |= gpu_shared::kProbeOptionCacheCheck;
  f.options = glm::uvec4(options, std::uint32_t(selectionFrame), s.sleepPeriod, s.maxSteps);
  f.trace = glm::vec4(s.hitEpsilon, s.relocationMinDistance, s.sleepThreshold, s.traceDistance);
  // w: vigilant updates when new (bits 0-7), near a moving object (bits 8-15), after a light
  // switch (bits 16-23), and the closing updates that take a running mean (bits 24-31).
  const std::uint32_t switchVigilance =
      in.lightSwitchVigilantUpdates > 0 ? in.lightSwitchVigilantUpdates : s.switchVigilantUpdates();
  f.selection = glm::uvec4(gpu_shared::kProbeClassCount, s.listCapacity(cascades), slots,
                           std::min(s.vigilantFrames, 255u) |
                               (std::min(s.objectVigilantFrames, 255u) << 8u) |
                               (std::min(switchVigilance, 255u) << 16u) |
                               (std::min(s.vigilantMeanUpdates, 255u) << 24u));
  f.worldToStack = glm::vec4(glm::vec3(stack.cascade0MinWorld),
                             stack.voxelSize0 > 0.0 ? float(1.0 / stack.voxelSize0) : 0.0f);
  // Bounce cells: shared for several updates only where the field is calm. While every probe
  // is new, and in a light switch's vigilance, the bounces build up one per update, and a cell
  // looked up an update ago would hold each of them back an update.
  if (first_) buildingUntil_ = std::max(buildingUntil_, updates_ + s.vigilantFrames);
  if (in.lightsChanged) buildingUntil_ = std::max(buildingUntil_, updates_ + switchVigilance);
  const bool building = updates_ < buildingUntil_ || in.lightSwitchCatchUp;
  // While the lights drift a cell serves half as long: its E follows the light, and the GPU and
  // the CPU reference, which may look a grazing ray's cell up in different updates, part for at
  // most that long (ProbeLightDriftTest.GpuMatchesCpuThroughDriftingFrames: 9.8e-3 at 8 updates,
  // 4.5e-2 at 16).
  const std::uint32_t serves =
      drifting && s.bounceCellUpdates > 1 ? s.bounceCellUpdates / 2 : s.bounceCellUpdates;
  // z: where the bounce passes' list of waiting rays starts, after room for one cell per ray
  // (ProbeFieldSizes::bounceWork).
  // w: the near-field gather's rays and reach in eighths of a spacing (probe_near_field.glsl).
  const std::uint32_t nearRays = std::min(s.nearFieldRays, 255u);
  const std::uint32_t nearReach =
      std::uint32_t(std::clamp(std::lround(s.nearFieldReach * 8.0f), 1l, 255l));
  f.bounce = glm::uvec4(updates_, building ? std::min(serves, 1u) : serves,
                        s.listCapacity(cascades) * s.raysPerProbe, nearRays | nearReach << 8u);
  ++updates_;

  gridOrigins_ = std::move(gridOrigins);
  windowWorld_ = std::move(windowWorld);
  pageTables_ = stack.pageTables;
  driftedBefore_ = drifting;
  first_ = false;
  return out;
}

}  // namespace sdfstream::probe
