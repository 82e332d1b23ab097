#include "tools/render_args.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.h"

namespace sdfstream::cli {
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

std::set<std::string> renderValueOptions(std::set<std::string> own) {
  own.insert({"--gi", "--gi-frames", "--probe-rays", "--probe-budget", "--relight-pages", "--sun",
              "--sky", "--exposure", "--direct", "--cards"});
  return own;
}

const char* const kStillGiFramesHelp =
    "  --gi-frames N                     GI frames run before a still image, camera fixed, so the\n"
    "                                    probes converge (default 24)\n";

const char* const kRenderHelp =
    "  --gi on|off                       global illumination from the probe field (default on;\n"
    "                                    off: direct light only; --cpu implies off)\n"
    "  --probe-rays N                    rays per probe per GI frame (default 128)\n"
    "  --probe-budget N                  probe rays per GI frame, all cascades (default 1048576;\n"
    "                                    fly on a CPU Vulkan device: 65536); probes beyond it\n"
    "                                    wait for later frames, nearest and in view first\n"
    "  --relight-pages N|all             light-cache pages relit per frame at most: new bricks\n"
    "                                    first, then the longest out of date (default all;\n"
    "                                    fly: 256, on a CPU Vulkan device 64)\n"
    "  --sun dx,dy,dz,E                  sun: direction its light travels (world, e.g. 0,-1,0 =\n"
    "                                    straight down) and irradiance E (0 = no sun; default\n"
    "                                    0.45,-0.7,-0.55,3); a world imported with lights of\n"
    "                                    its own (glTF KHR_lights_punctual) is lit by those\n"
    "                                    unless --sun is given\n"
    "  --sky r,g,b[,r,g,b]               sky radiance at the zenith [and at the horizon; one\n"
    "                                    colour = constant sky] (default 0.06,0.11,0.25,\n"
    "                                    0.2,0.22,0.26)\n"
    "  --exposure EV                     exposure in stops before the ACES tone map (default 0)\n"
    "  --direct pixel|cache              direct light per pixel with SDF soft shadows (default),\n"
    "                                    or the light cache's value of the hit voxel\n"
    "  --cards on|off                    moving objects' card atlases (default on): probe rays\n"
    "                                    that hit an object read the light it receives; off: an\n"
    "                                    object bounces only its emission and probe light\n";

RenderOptions renderOptionsFromArgs(const Args& args, bool cpu, int defaultGiFrames,
                                    std::uint32_t defaultProbeBudget,
                                    std::uint32_t defaultRelightBudget) {
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
  o.renderer.settings.light.relightPageBudget = defaultRelightBudget;
  if (auto pages = args.value("--relight-pages"))
    o.renderer.settings.light.relightPageBudget =
        *pages == "all" ? kRelightEveryPage
                        : std::uint32_t(args.integer("--relight-pages", 0, 1, 1 << 20));
  const std::string direct = args.value("--direct").value_or("pixel");
  if (direct != "pixel" && direct != "cache")
    throw usage("--direct expects pixel or cache, got '" + direct + "'");
  o.renderer.shading.direct =
      direct == "pixel" ? gpu_shared::kShadeDirectPixel : gpu_shared::kShadeDirectCache;
  o.renderer.shading.shadowSteps = o.renderer.settings.light.maxShadowSteps;
  o.renderer.shading.shadowEpsilon = o.renderer.settings.light.hitEpsilon;
  o.exposureStops = float(args.number("--exposure", 0.0));
  const std::string cards = args.value("--cards").value_or("on");
  if (cards != "on" && cards != "off")
    throw usage("--cards expects on or off, got '" + cards + "'");
  o.renderer.settings.objects.cards = cards == "on";

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
  o.packLights = !args.has("--sun");
  return o;
}

const char* const kPrimaryHelp =
    "  --mesh SCENE                      glTF/GLB/OBJ/layout JSON in the pack's world frame\n"
    "                                    (usually what it was imported from): its triangles are\n"
    "                                    rasterized as the primary surfaces, lit by the same\n"
    "                                    direct light and probes\n"
    "  --primary raster|sdf              primary surfaces (default: raster with --mesh, else\n"
    "                                    the SDF's, traced)\n";

std::filesystem::path primaryMeshFromArgs(const Args& args, bool cpu) {
  const auto mesh = args.value("--mesh");
  const std::string primary = args.value("--primary").value_or(mesh ? "raster" : "sdf");
  if (primary != "raster" && primary != "sdf")
    throw usage("--primary expects raster or sdf, got '" + primary + "'");
  if (primary == "sdf") return {};
  if (!mesh) throw usage("--primary raster needs --mesh SCENE (the triangles to rasterize)");
  if (cpu) throw usage("--primary raster needs Vulkan (drop --cpu, or use --primary sdf)");
  return *mesh;
}

}  // namespace sdfstream::cli
