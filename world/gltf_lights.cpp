#include "world/gltf_lights.h"

#include <cmath>

#include "core/error.h"

namespace sdfstream::gltf {
namespace {

using Kind = InputErrorKind;
constexpr const char* kExtension = "KHR_lights_punctual";
constexpr double kPi = 3.14159265358979323846;

}  // namespace

std::vector<SceneLight> readLightDefinitions(const Json& json, const std::string& file) {
  const JsonReader root(json, "root", file);
  const Json* ext = root.extension(kExtension);
  if (!ext) return {};
  const std::string where = std::string("extensions.") + kExtension;
  auto list = ext->find("lights");
  if (list == ext->end()) return {};
  if (!list->is_array()) throw InputError(Kind::Malformed, file, where + ".lights: expected an array");
  if (list->size() > kMaxGltfLights)
    throw InputError(Kind::TooLarge, file,
                     where + ": " + std::to_string(list->size()) + " lights, at most " +
                         std::to_string(kMaxGltfLights));
  std::vector<SceneLight> lights;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const JsonReader r((*list)[i], where + ".lights[" + std::to_string(i) + "]", file);
    SceneLight l;
    const std::string type = r.string("type", "");
    if (type == "directional") l.type = SceneLight::Type::Sun;
    else if (type == "point") l.type = SceneLight::Type::Point;
    else if (type == "spot") l.type = SceneLight::Type::Spot;
    else r.fail("type", "expected directional, point or spot");
    double color[3] = {1.0, 1.0, 1.0};
    r.numbers("color", color, 3);
    const double intensity = r.number("intensity", 1.0);
    const double range = r.number("range", 0.0);
    if (!std::isfinite(color[0] + color[1] + color[2] + intensity + range) || intensity < 0.0 ||
        range < 0.0 || color[0] < 0.0 || color[1] < 0.0 || color[2] < 0.0)
      r.fail("intensity", "colour, intensity and range must be finite and >= 0");
    l.color = glm::vec3(float(color[0]), float(color[1]), float(color[2]));
    l.intensity = float(intensity);
    l.range = l.type == SceneLight::Type::Sun ? 0.0f : float(range);
    l.position = glm::dvec3(0.0);
    l.direction = glm::vec3(0.0f, 0.0f, -1.0f);
    if (l.type == SceneLight::Type::Spot) {
      double inner = 0.0, outer = kPi / 4.0;  // the extension's defaults
      if (auto spot = (*list)[i].find("spot"); spot != (*list)[i].end()) {
        const JsonReader s(*spot, r.where() + ".spot", file);
        inner = s.number("innerConeAngle", inner);
        outer = s.number("outerConeAngle", outer);
        if (!(inner >= 0.0 && inner < outer && outer <= kPi / 2.0))
          s.fail("outerConeAngle", "expected 0 <= innerConeAngle < outerConeAngle <= pi/2");
      }
      l.innerConeDegrees = float(inner * 180.0 / kPi);
      l.outerConeDegrees = float(outer * 180.0 / kPi);
    }
    lights.push_back(l);
  }
  return lights;
}

int nodeLight(const Json& json, std::size_t node, std::size_t definitions,
              const std::string& file) {
  auto nodes = json.find("nodes");
  if (nodes == json.end() || !nodes->is_array() || node >= nodes->size()) return -1;
  const Json& n = (*nodes)[node];
  const std::string where = "nodes[" + std::to_string(node) + "]";
  const JsonReader r(n, where, file);
  const Json* ext = r.extension(kExtension);
  if (!ext) return -1;
  const JsonReader e(*ext, where + ".extensions." + kExtension, file);
  const std::size_t light = e.index("light");
  if (light >= definitions)
    throw InputError(Kind::OutOfRange, file,
                     e.where() + ".light: light " + std::to_string(light) + " does not exist");
  return int(light);
}

}  // namespace sdfstream::gltf
