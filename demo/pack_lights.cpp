#include "demo/pack_lights.h"

#include <algorithm>
#include <cstdio>
#include <system_error>
#include <vector>

#include "shaders/shared/light_layout.h"
#include "world/pack.h"
#include "world/pack_format.h"

namespace sdfstream {

std::size_t usePackLights(RenderOptions& options, const std::filesystem::path& world) {
  if (!options.packLights) return 0;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(world / pack_format::kManifestFile, ec)) return 0;
  return useOwnLights(options, readManifest(world).lights, world.string());
}

std::size_t useOwnLights(RenderOptions& options, std::vector<SceneLight> lights,
                         const std::string& from) {
  if (!options.packLights || lights.empty()) return 0;
  if (lights.size() > gpu_shared::kMaxLights) {
    std::stable_sort(lights.begin(), lights.end(), [](const SceneLight& a, const SceneLight& b) {
      return a.intensity * glm::length(a.color) > b.intensity * glm::length(b.color);
    });
    std::fprintf(stderr, "note: %s has %zu lights of its own; the %u brightest are used\n",
                 from.c_str(), lights.size(), gpu_shared::kMaxLights);
    lights.resize(gpu_shared::kMaxLights);
  }
  options.lights.lights = std::move(lights);
  ++options.lights.version;
  return options.lights.lights.size();
}

}  // namespace sdfstream
