#include "bench/bench_gi_scenes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/hash.h"
#include "shaders/shared/light_layout.h"
#include "world/cornell_light.h"
#include "world/gltf_import.h"
#include "world/mesh_source.h"
#include "world/obj_import.h"
#include "world/pack_import.h"
#include "world/scene_layout.h"

namespace sdfstream::bench {
namespace {

namespace fs = std::filesystem;
using reference::PinholeCamera;

std::uint32_t addMaterial(TriangleScene& s, glm::vec3 albedo, const std::string& name) {
  Material m;
  m.baseColorFactor = glm::vec4(albedo, 1.0f);
  m.name = name;
  s.materials.push_back(m);
  return std::uint32_t(s.materials.size() - 1);
}

void addQuad(TriangleScene& s, const glm::vec3 (&q)[4], std::uint32_t material) {
  const auto base = std::uint32_t(s.positions.size());
  for (const glm::vec3& p : q) {
    s.positions.push_back(p);
    s.uvs.push_back(glm::vec2(0.0f));
  }
  s.triangles.push_back({base, base + 1, base + 2});
  s.triangles.push_back({base, base + 2, base + 3});
  s.triangleMaterial.insert(s.triangleMaterial.end(), 2, material);
}

// The Cornell box from Cornell University's published measurements (millimetres; "Cornell Box
// Data", graphics.cornell.edu/online/box/data.html), turned into McGuire's frame (metres, red wall
// at -x, open side at +z, y up): x' = (278 - x)/1000, y' = y/1000, z' = (279.6 - z)/1000 (a
// rotation by 180 degrees about y, so windings and handedness are kept). Reflectances: McGuire's
// RGB fit of the measured spectra (the values of CornellBox-Original.mtl); light Ke 17 12 4.
TriangleScene builtInCornellBox() {
  TriangleScene s;
  s.source = "built-in Cornell box";
  const glm::vec3 white(0.725f, 0.71f, 0.68f), red(0.63f, 0.065f, 0.05f),
      green(0.14f, 0.45f, 0.091f);
  const std::uint32_t mWhite = addMaterial(s, white, "white"),
                      mRed = addMaterial(s, red, "leftWall"),
                      mGreen = addMaterial(s, green, "rightWall");
  Material light;
  light.baseColorFactor = glm::vec4(0.78f, 0.78f, 0.78f, 1.0f);
  light.emissive = glm::vec3(17.0f, 12.0f, 4.0f);
  light.name = "light";
  s.materials.push_back(light);
  const auto mLight = std::uint32_t(s.materials.size() - 1);
  auto P = [](float x, float y, float z) {
    return glm::vec3((278.0f - x) / 1000.0f, y / 1000.0f, (279.6f - z) / 1000.0f);
  };
  const glm::vec3 quads[][4] = {
      {P(552.8f, 0, 0), P(0, 0, 0), P(0, 0, 559.2f), P(549.6f, 0, 559.2f)},  // floor
      {P(556, 548.8f, 0), P(556, 548.8f, 559.2f), P(0, 548.8f, 559.2f),
       P(0, 548.8f, 0)},  // ceiling
      {P(549.6f, 0, 559.2f), P(0, 0, 559.2f), P(0, 548.8f, 559.2f),
       P(556, 548.8f, 559.2f)},  // back
  };
  for (const auto& q : quads) addQuad(s, q, mWhite);
  addQuad(s, {P(0, 0, 559.2f), P(0, 0, 0), P(0, 548.8f, 0), P(0, 548.8f, 559.2f)}, mGreen);
  addQuad(s, {P(552.8f, 0, 0), P(549.6f, 0, 559.2f), P(556, 548.8f, 559.2f), P(556, 548.8f, 0)},
          mRed);
  // The light sits 0.5 mm below the ceiling so the two surfaces never coincide.
  addQuad(s, {P(343, 548.3f, 227), P(343, 548.3f, 332), P(213, 548.3f, 332), P(213, 548.3f, 227)},
          mLight);
  const glm::vec3 shortBlock[][4] = {
      {P(130, 165, 65), P(82, 165, 225), P(240, 165, 272), P(290, 165, 114)},
      {P(290, 0, 114), P(290, 165, 114), P(240, 165, 272), P(240, 0, 272)},
      {P(130, 0, 65), P(130, 165, 65), P(290, 165, 114), P(290, 0, 114)},
      {P(82, 0, 225), P(82, 165, 225), P(130, 165, 65), P(130, 0, 65)},
      {P(240, 0, 272), P(240, 165, 272), P(82, 165, 225), P(82, 0, 225)}};
  const glm::vec3 tallBlock[][4] = {
      {P(423, 330, 247), P(265, 330, 296), P(314, 330, 456), P(472, 330, 406)},
      {P(423, 0, 247), P(423, 330, 247), P(472, 330, 406), P(472, 0, 406)},
      {P(472, 0, 406), P(472, 330, 406), P(314, 330, 456), P(314, 0, 456)},
      {P(314, 0, 456), P(314, 330, 456), P(265, 330, 296), P(265, 0, 296)},
      {P(265, 0, 296), P(265, 330, 296), P(423, 330, 247), P(423, 0, 247)}};
  for (const auto& q : shortBlock) addQuad(s, q, mWhite);
  for (const auto& q : tallBlock) addQuad(s, q, mWhite);
  return s;
}

PinholeCamera lookAt(glm::vec3 from, glm::vec3 to, float fov) {
  PinholeCamera c;
  c.position = from;
  c.forward = to - from;
  c.up = glm::vec3(0.0f, 1.0f, 0.0f);
  c.verticalFovDegrees = fov;
  return c;
}

// The glTF file's own cameras (root nodes with TRS and a perspective camera), in file order.
// A glTF camera looks down its local -z with +y up.
std::vector<std::pair<std::string, PinholeCamera>> gltfCameras(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  std::vector<std::pair<std::string, PinholeCamera>> out;
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.contains("nodes") || !j.contains("cameras")) return out;
  for (const auto& n : j["nodes"]) {
    if (!n.contains("camera") || n.contains("matrix")) continue;
    const auto& cam = j["cameras"][n["camera"].get<std::size_t>()];
    if (!cam.contains("perspective")) continue;
    glm::quat q(1.0f, 0.0f, 0.0f, 0.0f);
    glm::vec3 t(0.0f);
    if (n.contains("rotation")) {
      const auto& r = n["rotation"];
      q = glm::quat(r[3].get<float>(), r[0].get<float>(), r[1].get<float>(), r[2].get<float>());
    }
    if (n.contains("translation")) {
      const auto& v = n["translation"];
      t = glm::vec3(v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
    }
    PinholeCamera c;
    c.position = t;
    c.forward = glm::normalize(q) * glm::vec3(0.0f, 0.0f, -1.0f);
    c.up = glm::normalize(q) * glm::vec3(0.0f, 1.0f, 0.0f);
    c.verticalFovDegrees = glm::degrees(cam["perspective"].value("yfov", 0.785f));
    out.emplace_back(n.value("name", "camera"), c);
  }
  return out;
}

void describeBounds(const TriangleScene& s) {
  const glm::vec3 lo = s.boundsMin(), hi = s.boundsMax();
  std::printf("      %zu triangles, bounds (%.2f %.2f %.2f) .. (%.2f %.2f %.2f) m\n",
              s.triangles.size(), lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
}

BenchScene cornellBox(const fs::path& dataDir) {
  BenchScene b;
  b.name = "cornell-box";
  const fs::path glb = dataDir / "cornell-box" / "CornellBox-Original.glb";
  TriangleScene s;
  if (fs::exists(glb)) {
    s = loadGltf(glb);
    b.packSource = glb;
    b.description = "McGuire's CornellBox-Original.glb";
  } else {
    s = builtInCornellBox();
    b.description = "built in code from Cornell's measurements (data folder absent)";
  }
  // Hard shadows, as the reference casts them.
  const SceneLight spot = cornellSpotFromEmitters(s, 0.0f);
  b.lights.lights.push_back(spot);
  char intensity[32];
  std::snprintf(intensity, sizeof intensity, "%.2f", spot.intensity);
  b.description += std::string(
                       "; ceiling light as a downward spot light (hard shadows) of on-axis "
                       "intensity Ke·A = ") +
                   intensity + " (quad emission removed); black sky";
  const glm::vec3 lo = s.boundsMin(), hi = s.boundsMax(), e = hi - lo, mid = 0.5f * (lo + hi);
  b.voxelSize = double(std::max({e.x, e.y, e.z})) / 100.0;  // the box fills 100 of cascade 0's 128
  b.lods = 3;
  b.defaultCascades = 1;  // the whole box is inside cascade 0; nothing lies beyond its open side
  b.cascadeSweep = {1, 2, 3};
  b.streamCamera = glm::dvec3(mid);
  b.viewDirection = glm::vec3(0.0f, 0.0f, -1.0f);
  // The classic view through the open side (+z), and one from inside a top front corner.
  const float dist = 0.5f * e.y / std::tan(glm::radians(20.0f)) + 0.1f * e.z;
  b.views.push_back(lookAt(glm::vec3(mid.x, mid.y, hi.z + dist), mid, 40.0f));
  b.viewNames.push_back("front");
  b.views.push_back(lookAt(lo + e * glm::vec3(0.2f, 0.85f, 0.95f),
                           lo + e * glm::vec3(0.75f, 0.15f, 0.25f), 60.0f));
  b.viewNames.push_back("corner");
  b.triangles = std::make_unique<TriangleScene>(std::move(s));
  return b;
}

SceneSky daySky() {
  SceneSky sky;
  sky.zenith = glm::vec3(0.25f, 0.38f, 0.65f);
  sky.horizon = glm::vec3(0.55f, 0.58f, 0.62f);
  return sky;
}

SceneLight sun(glm::vec3 direction, float irradiance) {
  SceneLight l;
  l.type = SceneLight::Type::Sun;
  l.direction = glm::normalize(direction);
  l.color = glm::vec3(1.0f, 0.95f, 0.85f);
  l.intensity = irradiance;
  l.shadowSharpness = 0.0f;  // hard shadows, as the reference casts them
  return l;
}

std::optional<BenchScene> gltfScene(const std::string& name, const fs::path& file, double voxel,
                                    int lods, int defaultCascades, std::vector<int> sweep,
                                    SceneLight key, std::size_t maxViews, std::string* skip) {
  if (!fs::exists(file)) {
    *skip = name + ": " + file.string() + " not found, skipped";
    return std::nullopt;
  }
  BenchScene b;
  b.name = name;
  b.packSource = file;
  TriangleScene s = loadGltf(file);
  describeBounds(s);
  b.voxelSize = voxel;
  b.lods = lods;
  b.defaultCascades = defaultCascades;
  b.cascadeSweep = std::move(sweep);
  // A file with lights of its own (KHR_lights_punctual) is lit by them, GI and reference alike;
  // the scene's key light stands in only where it has none.
  const bool ownLights = !s.lights.empty() && s.lights.size() <= gpu_shared::kMaxLights;
  if (ownLights)
    b.lights.lights = s.lights;
  else
    b.lights.lights.push_back(key);
  b.lights.sky = daySky();
  for (auto& [camName, cam] : gltfCameras(file)) {
    if (b.views.size() >= maxViews) break;
    b.views.push_back(cam);
    b.viewNames.push_back(camName);
  }
  if (b.views.empty()) {
    const glm::vec3 lo = s.boundsMin(), hi = s.boundsMax();
    b.views.push_back(lookAt(lo + (hi - lo) * glm::vec3(0.85f, 0.35f, 0.5f),
                             lo + (hi - lo) * glm::vec3(0.1f, 0.3f, 0.5f), 60.0f));
    b.viewNames.push_back("bounds");
  }
  // The player stands in the middle of the scene, looking where the first view looks: the
  // stack (and the finest probes) centre there, so every view's points are covered.
  b.streamCamera = 0.5 * (glm::dvec3(s.boundsMin()) + glm::dvec3(s.boundsMax()));
  b.viewDirection = glm::normalize(b.views[0].forward);
  b.description = file.filename().string() + " (" + std::to_string(s.triangles.size()) +
                  " triangles, views: the file's cameras); " +
                  (ownLights ? std::to_string(s.lights.size()) + " lights of the file's own"
                             : std::string("sun (hard shadows)")) +
                  " + sky";
  b.triangles = std::make_unique<TriangleScene>(std::move(s));
  return b;
}

BenchScene bunnyScene(std::string* skip) {
  BenchScene b;
  b.name = "bunny";
  const fs::path obj = "/usr/share/glmark2/models/bunny.obj";
  if (!fs::exists(obj)) {
    *skip = "bunny: " + obj.string() + " not found (Debian glmark2-data), skipped";
    return b;
  }
  b.packSource = obj;
  const TriangleScene bunny = loadObj(obj);
  TriangleScene s;
  s.source = "bunny on a slab";
  // Bunny scaled to 1 m tall, standing on the slab's top at y = 0.
  const glm::vec3 lo = bunny.boundsMin(), hi = bunny.boundsMax();
  const float scale = 1.0f / (hi.y - lo.y);
  glm::dmat4 m(1.0);
  m = glm::scale(glm::translate(m, glm::dvec3(-0.5 * (lo.x + hi.x) * scale, -lo.y * scale,
                                              -0.5 * (lo.z + hi.z) * scale)),
                 glm::dvec3(scale));
  appendTransformed(s, bunny, m);
  const std::uint32_t ground = addMaterial(s, glm::vec3(0.45f, 0.42f, 0.38f), "ground");
  const float h = 2.0f, t = 0.1f;  // 4 m x 4 m slab, 10 cm thick (closed box)
  const glm::vec3 c[8] = {{-h, -t, -h}, {h, -t, -h}, {h, -t, h}, {-h, -t, h},
                          {-h, 0, -h},  {h, 0, -h},  {h, 0, h},  {-h, 0, h}};
  addQuad(s, {c[4], c[7], c[6], c[5]}, ground);
  addQuad(s, {c[0], c[1], c[2], c[3]}, ground);
  addQuad(s, {c[0], c[4], c[5], c[1]}, ground);
  addQuad(s, {c[1], c[5], c[6], c[2]}, ground);
  addQuad(s, {c[2], c[6], c[7], c[3]}, ground);
  addQuad(s, {c[3], c[7], c[4], c[0]}, ground);
  describeBounds(s);
  b.voxelSize = 0.02;
  b.lods = 4;
  b.defaultCascades = 3;
  b.cascadeSweep = {2, 3, 4};
  b.lights.lights.push_back(sun(glm::vec3(-0.5f, -0.8f, -0.35f), 3.0f));
  b.lights.sky = daySky();
  b.streamCamera = glm::dvec3(0.0, 0.6, 1.2);
  b.viewDirection = glm::normalize(glm::vec3(0.0f, -0.3f, -1.0f));
  b.views.push_back(lookAt(glm::vec3(0.0f, 0.7f, 2.2f), glm::vec3(0.0f, 0.4f, 0.0f), 50.0f));
  b.viewNames.push_back("front");
  b.views.push_back(lookAt(glm::vec3(1.6f, 1.2f, -1.2f), glm::vec3(0.0f, 0.3f, 0.0f), 50.0f));
  b.viewNames.push_back("back");
  b.description = "glmark2's bunny (1 m) on a 4 m slab; sun + sky";
  b.triangles = std::make_unique<TriangleScene>(std::move(s));
  return b;
}

// A closed box [lo, hi] as six outward-facing quads.
void addBox(TriangleScene& s, glm::vec3 lo, glm::vec3 hi, std::uint32_t material) {
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z},
                          {lo.x, lo.y, hi.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z},
                          {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  addQuad(s, {c[4], c[7], c[6], c[5]}, material);  // top
  addQuad(s, {c[0], c[1], c[2], c[3]}, material);  // bottom
  addQuad(s, {c[0], c[4], c[5], c[1]}, material);  // -z
  addQuad(s, {c[1], c[5], c[6], c[2]}, material);  // +x
  addQuad(s, {c[2], c[6], c[7], c[3]}, material);  // +z
  addQuad(s, {c[3], c[7], c[4], c[0]}, material);  // -x
}

// Sponza's failure in small: a courtyard open to the sky inside a covered arcade, lit by the sky
// alone, larger than cascade 0 so that probe rays cross several cascades before they reach the
// sky. 16 x 16 m open court; around it a 4 m deep arcade (floor, 0.4 m roof slab at 5 m, square
// pillars every 4 m on the court side) closed by 0.4 m outer walls 9 m tall; 24.8 m across.
TriangleScene builtInCourtyard() {
  TriangleScene s;
  s.source = "built-in courtyard";
  const std::uint32_t stone = addMaterial(s, glm::vec3(0.6f, 0.55f, 0.48f), "stone");
  const std::uint32_t ground = addMaterial(s, glm::vec3(0.45f, 0.42f, 0.36f), "ground");
  const float court = 8.0f, arcade = 4.0f, wall = 0.4f, outer = court + arcade + wall;
  const float roofLo = 5.0f, roofHi = 5.4f, wallTop = 9.0f, pillar = 0.5f;
  addBox(s, {-outer, -0.3f, -outer}, {outer, 0.0f, outer}, ground);  // floor slab
  // Outer walls.
  addBox(s, {-outer, 0.0f, -outer}, {outer, wallTop, -outer + wall}, stone);
  addBox(s, {-outer, 0.0f, outer - wall}, {outer, wallTop, outer}, stone);
  addBox(s, {-outer, 0.0f, -outer + wall}, {-outer + wall, wallTop, outer - wall}, stone);
  addBox(s, {outer - wall, 0.0f, -outer + wall}, {outer, wallTop, outer - wall}, stone);
  // The arcade's roof: a frame of four slabs around the open court.
  const float in = outer - wall;
  addBox(s, {-in, roofLo, -in}, {in, roofHi, -court}, stone);
  addBox(s, {-in, roofLo, court}, {in, roofHi, in}, stone);
  addBox(s, {-in, roofLo, -court}, {-court, roofHi, court}, stone);
  addBox(s, {court, roofLo, -court}, {in, roofHi, court}, stone);
  // Pillars along the court's edge, every 4 m (corners included).
  for (float a = -court; a <= court + 1e-3f; a += 4.0f)
    for (const glm::vec2 at :
         {glm::vec2(a, -court), glm::vec2(a, court), glm::vec2(-court, a), glm::vec2(court, a)}) {
      const glm::vec3 c(at.x, 0.0f, at.y);
      addBox(s, c - glm::vec3(pillar * 0.5f, 0.0f, pillar * 0.5f),
             c + glm::vec3(pillar * 0.5f, roofLo, pillar * 0.5f), stone);
    }
  return s;
}

BenchScene courtyardScene(bool withSun) {
  BenchScene b;
  b.name = withSun ? "courtyard-sun" : "courtyard";
  TriangleScene s = builtInCourtyard();
  describeBounds(s);
  b.voxelSize = 0.05;  // cascade 0 = 6.4 m: the court alone spans cascades 0-2, the walls 3
  b.lods = 4;
  b.defaultCascades = 4;
  b.cascadeSweep = {2, 3, 4};
  b.lights.sky = daySky();  // sky only: every bit of light comes through the open roof
  if (withSun) b.lights.lights.push_back(sun(glm::vec3(0.3f, -1.0f, 0.25f), 4.0f));  // Sponza's
  b.streamCamera = glm::dvec3(0.0, 1.7, 2.0);
  b.viewDirection = glm::normalize(glm::vec3(0.0f, -0.2f, -1.0f));
  // Across the court to the far arcade; and from inside the arcade, out into the court.
  b.views.push_back(lookAt(glm::vec3(0.0f, 1.7f, 7.0f), glm::vec3(0.0f, 2.0f, -12.0f), 70.0f));
  b.viewNames.push_back("court");
  b.views.push_back(lookAt(glm::vec3(-10.0f, 1.7f, 10.0f), glm::vec3(4.0f, 1.0f, -2.0f), 70.0f));
  b.viewNames.push_back("arcade");
  b.description =
      "built-in courtyard (16 m open court in a 4 m deep covered arcade, 24.8 m across, "
      "larger than cascade 0); " +
      std::string(withSun ? "Sponza's sun (hard shadows) + sky" : "sky only");
  b.triangles = std::make_unique<TriangleScene>(std::move(s));
  return b;
}
// An interior lit only by what it emits: a closed 6 x 3 x 8 m room (0.2 m walls, no window, no
// sun, a black sky) with two warm panels hanging 0.4 m below the ceiling, a blue screen standing
// 0.3 m off a wall, a red wall, a table and a shelf. Every bit of light reaches a receiver
// through the probes (emission is the light cache's, no delta light): DDGI's emissive case, with
// emitters a few probe spacings across and at least two voxels from any other surface, so no
// voxel of a wall takes an emitter's material.
TriangleScene builtInEmissiveRoom() {
  TriangleScene s;
  s.source = "built-in emissive room";
  const std::uint32_t plaster = addMaterial(s, glm::vec3(0.7f, 0.68f, 0.64f), "plaster");
  const std::uint32_t floor = addMaterial(s, glm::vec3(0.4f, 0.3f, 0.22f), "floor");
  const std::uint32_t red = addMaterial(s, glm::vec3(0.6f, 0.1f, 0.08f), "red");
  const std::uint32_t wood = addMaterial(s, glm::vec3(0.5f, 0.36f, 0.2f), "wood");
  auto emitter = [&](glm::vec3 albedo, glm::vec3 emission, const std::string& name) {
    const std::uint32_t m = addMaterial(s, albedo, name);
    s.materials[m].emissive = emission;
    return m;
  };
  const std::uint32_t panel = emitter(glm::vec3(0.8f), glm::vec3(4.0f, 3.6f, 2.9f), "panel");
  const std::uint32_t screen = emitter(glm::vec3(0.1f), glm::vec3(0.5f, 1.1f, 3.0f), "screen");
  const float x = 3.0f, z = 4.0f, h = 3.0f, w = 0.2f;
  addBox(s, {-x - w, -w, -z - w}, {x + w, 0.0f, z + w}, floor);    // floor slab
  addBox(s, {-x - w, h, -z - w}, {x + w, h + w, z + w}, plaster);  // ceiling slab
  // The walls meet the slabs and each other along shared edges: the mesh is open, as most
  // levels are, and imports as shells (world/mesh_to_sdf.h).
  addBox(s, {-x - w, 0.0f, -z - w}, {x + w, h, -z}, plaster);  // -z wall
  addBox(s, {-x - w, 0.0f, z}, {x + w, h, z + w}, plaster);    // +z wall
  addBox(s, {-x - w, 0.0f, -z}, {-x, h, z}, red);              // -x wall, red
  addBox(s, {x, 0.0f, -z}, {x + w, h, z}, plaster);            // +x wall
  // Two panels (2.4 x 1 m, 0.1 m thick) hanging 0.4 m below the ceiling.
  for (const float pz : {-2.0f, 2.0f})
    addBox(s, {-1.2f, h - 0.5f, pz - 0.5f}, {1.2f, h - 0.4f, pz + 0.5f}, panel);
  // A screen (1.6 x 0.9 m, 0.1 m thick) 0.3 m off the +x wall, a table below the first panel,
  // a shelf against the -z wall.
  addBox(s, {x - 0.4f, 1.0f, 0.5f}, {x - 0.3f, 1.9f, 2.1f}, screen);
  addBox(s, {-0.8f, 0.72f, -2.5f}, {0.8f, 0.78f, -1.5f}, wood);  // table top
  for (const glm::vec2 leg : {glm::vec2(-0.75f, -2.45f), glm::vec2(0.7f, -2.45f),
                              glm::vec2(-0.75f, -1.6f), glm::vec2(0.7f, -1.6f)})
    addBox(s, {leg.x, 0.0f, leg.y}, {leg.x + 0.05f, 0.72f, leg.y + 0.05f}, wood);
  addBox(s, {-2.5f, 0.0f, -z}, {-0.5f, 2.0f, -z + 0.4f}, wood);  // shelf against -z
  return s;
}

BenchScene emissiveRoomScene() {
  BenchScene b;
  b.name = "emissive-room";
  TriangleScene s = builtInEmissiveRoom();
  describeBounds(s);
  b.voxelSize = 0.05;  // cascade 0 = 6.4 m: the 8 m room needs cascade 1 at its ends
  b.lods = 3;
  b.defaultCascades = 2;
  b.cascadeSweep = {2, 3};
  b.lights.sky = SceneSky{};  // black: the room is closed anyway
  b.streamCamera = glm::dvec3(0.0, 1.6, 1.0);
  b.viewDirection = glm::normalize(glm::vec3(0.0f, -0.1f, -1.0f));
  b.views.push_back(lookAt(glm::vec3(1.5f, 1.6f, 3.6f), glm::vec3(-0.5f, 0.8f, -3.0f), 70.0f));
  b.viewNames.push_back("room");
  b.views.push_back(lookAt(glm::vec3(-2.4f, 1.4f, -0.5f), glm::vec3(3.0f, 1.2f, 1.5f), 70.0f));
  b.viewNames.push_back("screen");
  b.description =
      "built-in emissive room (6 x 3 x 8 m, closed, no sun, black sky): lit only by two "
      "hanging panels and a blue screen";
  b.triangles = std::make_unique<TriangleScene>(std::move(s));
  return b;
}
}  // namespace

const std::vector<std::string>& benchSceneNames() {
  static const std::vector<std::string> names = {"cornell-box", "sponza",        "breakfast-room",
                                                 "courtyard",   "courtyard-sun", "emissive-room",
                                                 "large-world", "bunny"};
  return names;
}

namespace {
// The fewest cascades, at most the pack's LODs and never fewer than `fewest`, whose coarsest
// probe grid holds the scene's bounds around the player. A receiver beyond the coarsest grid has
// no cage of its own: it reads the border probes, whose rays left the stack there and brought
// back the sky (Sponza from its own cameras, 4 cascades: E/E_ref 1.25-2.19, relMSE 2.4-3.5).
// Cascade c's grid reaches 64 voxels of 2^c from the window's centre, less the page the window
// snaps by and half a probe spacing where the cascade blend needs it: 52 voxels of 2^c.
int cascadesCovering(const TriangleScene& s, glm::dvec3 player, double voxel, int lods,
                     int fewest) {
  const glm::dvec3 reach = glm::max(glm::abs(glm::dvec3(s.boundsMin()) - player),
                                    glm::abs(glm::dvec3(s.boundsMax()) - player));
  const double farthest = std::max({reach.x, reach.y, reach.z});
  int c = std::max(fewest, 1);
  while (c < lods && 52.0 * voxel * double(1 << (c - 1)) < farthest) ++c;
  return c;
}

std::optional<BenchScene> loadNamedScene(const std::string& name, const fs::path& dataDir,
                                         const fs::path& largeWorld, std::string* skip) {
  std::printf("scene %s\n", name.c_str());
  if (name == "cornell-box") {
    BenchScene b = cornellBox(dataDir);
    describeBounds(*b.triangles);
    return b;
  }
  // Sponza is about 30 m long: cascade 0 = 6.4 m at 5 cm; from its centre 4 cascades cover it.
  if (name == "sponza")
    return gltfScene(name, dataDir / "sponza" / "Sponza.gltf", 0.05, 5, 4, {2, 3, 5},
                     sun(glm::vec3(0.3f, -1.0f, 0.25f), 4.0f), 3, skip);
  // The Breakfast Room (3.7 m x 3 m x 4.7 m, window on +x) fits one cascade at 4 cm (5.12 m);
  // the sun comes in through the window.
  if (name == "breakfast-room")
    return gltfScene(name, dataDir / "breakfast-room" / "BreakfastRoom.gltf", 0.04, 3, 1, {1, 2, 3},
                     sun(glm::vec3(-0.55f, -0.6f, 0.6f), 4.0f), 2, skip);
  if (name == "courtyard" || name == "courtyard-sun")
    return courtyardScene(name == "courtyard-sun");
  if (name == "emissive-room") return emissiveRoomScene();
  if (name == "bunny") {
    BenchScene b = bunnyScene(skip);
    if (!b.triangles) return std::nullopt;
    return b;
  }
  if (name == "large-world") {
    if (!fs::exists(largeWorld / "manifest.json")) {
      *skip = "large-world: " + largeWorld.string() +
              " not found (sdfstream generate-world, then bench world), skipped";
      return std::nullopt;
    }
    BenchScene b;
    b.name = name;
    b.packSource = largeWorld;
    b.prebuiltPack = true;
    PackTileStore store(largeWorld);
    const PartitionSpec& spec = store.spec();
    b.voxelSize = spec.voxelSize;
    b.lods = spec.lodCount;
    b.defaultCascades = std::min(6, spec.lodCount);
    for (int c = 3; c <= b.defaultCascades; ++c) b.cascadeSweep.push_back(c);
    b.lights.lights.push_back(sun(glm::vec3(0.4f, -0.7f, 0.3f), 4.0f));
    b.lights.sky = daySky();
    const glm::dvec3 lo = store.manifest().boundsMin, hi = store.manifest().boundsMax;
    b.streamCamera = glm::dvec3(0.5 * (lo.x + hi.x), hi.y + 10.0, 0.5 * (lo.z + hi.z));
    b.viewDirection = glm::normalize(glm::vec3(1.0f, -0.35f, 0.2f));
    b.description = "the generated 4 km world pack (" +
                    std::to_string(store.manifest().tiles.size()) +
                    " tiles, v0 = " + std::to_string(spec.voxelSize) +
                    " m): timings and memory only, no triangle reference";
    return b;
  }
  *skip = name +
          ": unknown scene (cornell-box, sponza, breakfast-room, courtyard, courtyard-sun, "
          "emissive-room, bunny, large-world)";
  return std::nullopt;
}
}  // namespace

std::optional<BenchScene> loadBenchScene(const std::string& name, const fs::path& dataDir,
                                         const fs::path& largeWorld, std::string* skip) {
  const std::size_t at = name.find('@');
  if (at == std::string::npos) return loadNamedScene(name, dataDir, largeWorld, skip);
  std::optional<BenchScene> b = loadNamedScene(name.substr(0, at), dataDir, largeWorld, skip);
  if (!b) return b;
  // NAME@VIEW: that view alone, with the player -- the stack's centre -- at its camera, looking
  // where it looks, as a game's GI follows its camera. The scene's own player position serves
  // every view at once, so most of a view's points may lie in coarse cascades.
  const std::string view = name.substr(at + 1);
  std::size_t k = 0;
  while (k < b->viewNames.size() && b->viewNames[k] != view) ++k;
  if (k == b->viewNames.size() && !view.empty() &&
      view.find_first_not_of("0123456789") == std::string::npos && std::stoul(view) < k)
    k = std::stoul(view);
  if (k == b->viewNames.size()) {
    std::string names;
    for (const std::string& n : b->viewNames) names += (names.empty() ? "" : ", ") + n;
    *skip = name + ": no view '" + view + "' (views: " + names + ")";
    return std::nullopt;
  }
  const reference::PinholeCamera camera = b->views[k];
  b->views = {camera};
  b->viewNames = {b->viewNames[k]};
  b->streamCamera = glm::dvec3(camera.position);
  b->viewDirection = glm::normalize(camera.forward);
  b->description += "; view " + b->viewNames[0] + " alone, the player at its camera";
  if (b->triangles) {
    const int cascades =
        cascadesCovering(*b->triangles, b->streamCamera, b->voxelSize, b->lods, b->defaultCascades);
    if (cascades != b->defaultCascades)
      b->description += " (" + std::to_string(cascades) +
                        " cascades by default to hold the scene from there, not " +
                        std::to_string(b->defaultCascades) + ")";
    b->defaultCascades = cascades;
  }
  return b;
}

fs::path benchScenePack(const BenchScene& scene, const fs::path& cacheDir, double* importSeconds) {
  *importSeconds = 0.0;
  if (scene.prebuiltPack) return scene.packSource;
  // Key: the importer's revision (v2: samples at the band's edge read as the band), the source
  // file's identity (path, size, mtime) or, for built-in scenes, the triangles; plus everything
  // the importer is given.
  std::ostringstream key;
  key << "v2|" << scene.name << '|' << scene.voxelSize << '|' << scene.lods << '|';
  if (!scene.packSource.empty() && !fs::is_directory(scene.packSource)) {
    key << fs::absolute(scene.packSource).string() << '|' << fs::file_size(scene.packSource) << '|'
        << fs::last_write_time(scene.packSource).time_since_epoch().count();
  }
  const TriangleScene& t = *scene.triangles;
  key << '|' << checksum64(t.positions.data(), t.positions.size() * sizeof(glm::vec3)) << '|'
      << checksum64(t.triangles.data(), t.triangles.size() * sizeof(glm::uvec3)) << '|'
      << checksum64(t.triangleMaterial.data(), t.triangleMaterial.size() * 4);
  for (const Material& m : t.materials)
    key << '|' << m.baseColorFactor.x << ',' << m.baseColorFactor.y << ',' << m.baseColorFactor.z
        << ',' << m.emissive.x << ',' << m.emissive.y << ',' << m.emissive.z;
  const std::string k = key.str();
  const fs::path dir = cacheDir / (scene.name + "-" + toHex(checksum64(k.data(), k.size())));
  if (fs::exists(dir / "manifest.json")) return dir;

  const auto start = std::chrono::steady_clock::now();
  PackImportOptions options;
  options.voxelSize = scene.voxelSize;
  options.lodCount = scene.lods;
  options.tileVoxels = std::max(128, 8 << (scene.lods - 1));
  std::vector<std::unique_ptr<SdfSource>> sources;
  sources.push_back(makeMeshSource(t));
  const PartitionSpec spec = partitionFor(sources, options, scene.name);
  fs::create_directories(cacheDir);
  importPack(sources, dir, spec, options, scene.name);
  *importSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return dir;
}

StreamedStack streamStack(const PackTileStore& store, TileLoader& loader, const BenchScene& scene,
                          int cascades) {
  StreamedStack s;
  StreamingOptions so;
  so.cascades = cascades;
  s.stack = std::make_unique<CascadeStack>(store, loader, so);
  for (int i = 0; i < 400; ++i) {
    s.stack->update(scene.streamCamera, glm::dvec3(scene.viewDirection));
    if (s.stack->settled()) break;
    loader.waitIdle();
  }
  if (!s.stack->settled())
    throw std::runtime_error("bench gi: " + scene.name + ": the cascade stack did not settle");
  s.stack->takeDirtySlots();
  for (std::uint32_t i = 0; i < so.atlasSlots; ++i) s.allSlots.push_back(i);
  return s;
}

}  // namespace sdfstream::bench
