// Internal to the glTF importer: KHR_lights_punctual (point, spot, directional) as SceneLights.
// Spec: KhronosGroup/glTF extensions/2.0/Khronos/KHR_lights_punctual.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "world/gltf_json.h"
#include "world/scene_lights.h"

namespace sdfstream::gltf {

// The most lights one file may define and place; more is refused (TooLarge). The GI itself
// lights with at most 16 (gpu_shared::kMaxLights): whoever hands a scene's lights to it chooses.
inline constexpr std::size_t kMaxGltfLights = 1024;

// The file's light definitions (root extensions.KHR_lights_punctual.lights), in file order, in
// their own space: at the origin, pointing down -Z (transformLight places them). Units are taken as they are: intensity in
// candela (point, spot) or lux (directional) becomes SceneLight::intensity one to one, so a file
// lit for a physically based renderer needs its exposure set accordingly.
std::vector<SceneLight> readLightDefinitions(const Json& json, const std::string& file);

// The light a node places: light index from node.extensions.KHR_lights_punctual.light, or -1.
int nodeLight(const Json& json, std::size_t node, std::size_t definitions,
              const std::string& file);

}  // namespace sdfstream::gltf
