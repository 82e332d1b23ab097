#include "tools/view_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "core/error.h"

namespace sdfstream {
namespace {

std::vector<float> parseNumbers(const std::string& text) {
  std::vector<float> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      const float v = std::stof(item, &used);
      if (used != item.size() || !std::isfinite(v)) return {};
      out.push_back(v);
    } catch (const std::exception&) {
      return {};
    }
  }
  return out;
}

InputError usage(const std::string& problem) {
  return InputError(InputErrorKind::Usage, "command line", problem);
}

// Default light rig of the demo views: a warm sun from the front-left, high enough that the
// objects cast shadows onto the ground towards the back-right and both coloured walls of the demo
// scene are lit, and a blue gradient sky whose light fills the shadows through the probes.
constexpr glm::vec3 kSunTravel(0.45f, -0.7f, -0.55f);
constexpr float kSunIrradiance = 3.0f;
constexpr glm::vec3 kSkyZenith(0.06f, 0.11f, 0.25f);
constexpr glm::vec3 kSkyHorizon(0.2f, 0.22f, 0.26f);

}  // namespace

namespace cli {

std::set<std::string> renderValueOptions(std::set<std::string> own) {
  own.insert({"--gi", "--gi-frames", "--probe-rays", "--probe-budget", "--sun", "--sky",
              "--exposure", "--direct"});
  return own;
}

const char* const kStillGiFramesHelp =
    "  --gi-frames N                     GI frames run before a still image, camera fixed, so the\n"
    "                                    probes converge (default 24)\n";

const char* const kRenderHelp =
    "  --gi on|off                       global illumination from the probe field (default on;\n"
    "                                    off: direct light only; --cpu implies off)\n"
    "  --probe-rays N                    rays per probe per GI frame (default 128)\n"
    "  --probe-budget N                  probe rays per GI frame, all cascades (default 2097152;\n"
    "                                    fly on a CPU Vulkan device: 65536); probes beyond it\n"
    "                                    wait for later frames, nearest and in view first\n"
    "  --sun dx,dy,dz,E                  sun: direction its light travels (world, e.g. 0,-1,0 =\n"
    "                                    straight down) and irradiance E (0 = no sun; default\n"
    "                                    0.45,-0.7,-0.55,3)\n"
    "  --sky r,g,b[,r,g,b]               sky radiance at the zenith [and at the horizon; one\n"
    "                                    colour = constant sky] (default 0.06,0.11,0.25,\n"
    "                                    0.2,0.22,0.26)\n"
    "  --exposure EV                     exposure in stops before the ACES tone map (default 0)\n"
    "  --direct pixel|cache              direct light per pixel with SDF soft shadows (default),\n"
    "                                    or the light cache's value of the hit voxel\n";

RenderOptions renderOptionsFromArgs(const Args& args, bool cpu, int defaultGiFrames,
                                    std::uint32_t defaultProbeBudget) {
  RenderOptions o;
  const std::string gi = args.value("--gi").value_or(cpu ? "off" : "on");
  if (gi != "on" && gi != "off") throw usage("--gi expects on or off, got '" + gi + "'");
  if (gi == "on" && cpu)
    throw usage("--gi on needs Vulkan (the probe field has no CPU renderer); drop --cpu");
  o.gi = gi == "on";
  o.renderer.gi = o.gi;
  o.giFrames = args.integer("--gi-frames", defaultGiFrames, 1, 100000);
  o.renderer.settings.probes.raysPerProbe =
      std::uint32_t(args.integer("--probe-rays", int(gpu_shared::kProbeDefaultRays), 1, 1024));
  o.renderer.settings.probes.rayBudget =
      std::uint32_t(args.integer("--probe-budget", int(defaultProbeBudget), 1, 1 << 30));
  const std::string direct = args.value("--direct").value_or("pixel");
  if (direct != "pixel" && direct != "cache")
    throw usage("--direct expects pixel or cache, got '" + direct + "'");
  o.renderer.shading.direct =
      direct == "pixel" ? gpu_shared::kShadeDirectPixel : gpu_shared::kShadeDirectCache;
  o.renderer.shading.shadowSteps = o.renderer.settings.light.maxShadowSteps;
  o.renderer.shading.shadowEpsilon = o.renderer.settings.light.hitEpsilon;
  o.exposureStops = float(args.number("--exposure", 0.0));

  glm::vec3 sunDir = kSunTravel;
  float sunE = kSunIrradiance;
  if (auto text = args.value("--sun")) {
    const auto v = parseNumbers(*text);
    if (v.size() != 4 || v[3] < 0.0f ||
        (v[3] > 0.0f && glm::length(glm::vec3(v[0], v[1], v[2])) == 0.0f))
      throw usage("--sun expects dx,dy,dz,irradiance (a direction and a number >= 0), got '" +
                  *text + "'");
    sunDir = glm::vec3(v[0], v[1], v[2]);
    sunE = v[3];
    if (sunE == 0.0f) sunDir = glm::vec3(0.0f, -1.0f, 0.0f);
  }
  glm::vec3 zenith = kSkyZenith, horizon = kSkyHorizon;
  if (auto text = args.value("--sky")) {
    const auto v = parseNumbers(*text);
    const bool negative = std::any_of(v.begin(), v.end(), [](float x) { return x < 0.0f; });
    if ((v.size() != 3 && v.size() != 6) || negative)
      throw usage("--sky expects r,g,b or r,g,b,r,g,b (zenith, horizon; >= 0), got '" + *text +
                  "'");
    zenith = glm::vec3(v[0], v[1], v[2]);
    horizon = v.size() == 6 ? glm::vec3(v[3], v[4], v[5]) : zenith;
  }
  o.lights = defaultSceneLights(sunDir, sunE, zenith, horizon);
  return o;
}

}  // namespace cli

ViewRenderer::ViewRenderer(const World& world, gpu::Context* context, const RenderOptions& options,
                           TraceSettings trace)
    : world_(world), context_(context), options_(options) {
  options_.renderer.shading.trace = trace;
  options_.renderer.gi = options_.gi && context_;
  if (context_) gpu_ = std::make_unique<GiRenderer>(*context_, options_.renderer, 1u);
}

ViewRenderer::~ViewRenderer() = default;

void ViewRenderer::setObjects(DemoObjects* objects, int giFrames) {
  objects_ = objects;
  objectFrame_ = 0;
  objectTarget_ = objects ? framesOnWindow_ + giFrames : 0;
  if (gpu_) gpu_->setObjects(objects ? &objects->library : nullptr,
                             objects ? &objects->instances : nullptr);
}

ViewResult ViewRenderer::render(const Camera& camera, int width, int height) {
  const glm::ivec3 origin = cascadeOriginAround(world_, camera.target);
  if (!cascade_ || cascade_->originBrick != origin) {
    cascade_ = buildCascade(world_, origin);
    stack_ = std::make_unique<CascadeStackImage>(stackImageOf(*cascade_));
    framesOnWindow_ = 0;
  }
  ViewResult r;
  r.residentBricks = cascade_->residentBricks;
  r.cascadeBytes = cascade_->gpuBytes();
  const SceneLights& lights = options_.lights;

  if (!gpu_) {
    const auto rays = cameraRays(camera, width, height, *stack_);
    const auto gpuLights = toGpu(lights.lights, *stack_);
    auto start = std::chrono::steady_clock::now();
    if (options_.renderer.shading.direct == gpu_shared::kShadeDirectCache && framesOnWindow_ == 0) {
      cpuLight_.update(*stack_, gpuLights, toGpu(lights.sky),
                       lightDirtyPages(nullptr, *stack_, true), stack_->voxelSize0);
      ++framesOnWindow_;
    }
    const auto shaded = shadePrimaryCpu(*stack_, rays, gpuLights, toGpu(lights.sky),
                                        options_.renderer.shading, cpuLight_.radiance());
    r.shadeMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    r.rays = rays.size();
    r.frame = composeFrame(shaded, width, height, {}, {});
  } else {
    probe::ProbeFrameInputs inputs;
    inputs.cameraWorld = camera.position;
    inputs.viewDirection = glm::vec3(glm::normalize(camera.target - camera.position));
    auto step = [&] {
      if (objects_) objects_->apply(objectFrame_++ / 30.0);
      gpu_->update(*stack_, lights, inputs, frame_++);
      ++framesOnWindow_;
      const GiFrameTimes& t = gpu_->lastTimes();
      r.lightMilliseconds += t.gi.lightMilliseconds;
      r.objectMilliseconds += t.gi.objectMilliseconds;
      r.objectRays = t.gi.probes.objectRays;
      r.objectRayHits = t.gi.probes.objectHits;
      if (gpu_->giEnabled()) {
        r.probeMilliseconds.push_back(t.gi.probeMilliseconds);
        r.probePasses = t.probePasses;
      }
    };
    // The first frame uploads the stack, which the shading pass reads.
    if (framesOnWindow_ == 0) step();
    ShadedView view = gpu_->shade(camera, width, height, *stack_, lights);
    r.rays = view.rays.size();
    bool moved = false;  // objects moved after the view was shaded
    if (gpu_->giEnabled()) {
      // A fixed subset of this view's receivers tracks convergence frame by frame.
      std::vector<gpu_shared::ProbeQuery> subset;
      for (std::size_t i = 0; i < view.queries.size(); i += 61) subset.push_back(view.queries[i]);
      if (!r.probeMilliseconds.empty()) r.convergence.push_back(gpu_->meanIrradiance(subset));
      while (framesOnWindow_ < std::max(options_.giFrames, objectTarget_)) {
        step();
        moved = moved || objects_;
        r.convergence.push_back(gpu_->meanIrradiance(subset));
      }
      r.framesToConverge = framesToConverge(r.convergence);
    } else if (objects_) {
      while (framesOnWindow_ < objectTarget_) step(), moved = true;
    }
    // Shading does not depend on the probes, but it does on where the objects are.
    if (moved) view = gpu_->shade(camera, width, height, *stack_, lights);
    r.shadeMilliseconds = gpu_->lastTimes().shadeMilliseconds;
    r.frame = gpu_->finish(view);
    r.sampleMilliseconds = gpu_->lastTimes().sampleMilliseconds;
  }
  r.hits = r.frame.hits;
  r.objectHits = r.frame.objectHits;
  const float ev = options_.exposureStops;
  r.image = toneMap(r.frame.final(), width, height, ev, &r.nonFinite);
  r.directImage = toneMap(r.frame.direct, width, height, ev);
  r.indirectImage = toneMap(r.frame.indirect, width, height, ev);
  return r;
}

Camera defaultCamera(const World& world) {
  return frameBounds(world.worldMin(), world.worldMax(), glm::dvec3(0.55, 0.45, 1.0));
}

int framesToConverge(const std::vector<glm::vec3>& series, float tolerance) {
  if (series.empty()) return 0;
  const float last = luminance(series.back());
  int first = int(series.size()) - 1;
  for (int i = int(series.size()) - 1; i >= 0; --i) {
    if (std::abs(luminance(series[i]) - last) > tolerance * std::max(last, 1e-6f)) break;
    first = i;
  }
  return first + 1;  // frames run, counting from 1
}

}  // namespace sdfstream
