// A world pack's own lights (manifest "lights": a glTF scene's KHR_lights_punctual) in place of
// the command line's default sun, for render, fly and demo.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "demo/render_options.h"

namespace sdfstream {

// When options.packLights and `world` is a pack whose manifest lists lights, they replace
// options.lights.lights (the sky stays); at most gpu_shared::kMaxLights, the brightest by
// intensity × |colour| (a note on stderr says how many were left out). A .world file or a pack
// without lights changes nothing. Returns the number of the pack's lights now in use.
std::size_t usePackLights(RenderOptions& options, const std::filesystem::path& world);

// The same for lights already in hand (an imported scene's TriangleScene::lights); `from` names
// their source in the note.
std::size_t useOwnLights(RenderOptions& options, std::vector<SceneLight> lights,
                         const std::string& from);

}  // namespace sdfstream
