#include "demo/default_scene.h"

#include <system_error>

#include "core/error.h"

namespace fs = std::filesystem;

namespace sdfstream {

std::vector<fs::path> defaultSceneCandidates(const fs::path& executable) {
  const fs::path dir = executable.parent_path();
  return {dir / ".." / "share" / "sdfstream" / "default_scene.json",
          dir / "share" / "sdfstream" / "default_scene.json", fs::path(SDFSTREAM_SOURCE_SCENE)};
}

fs::path findDefaultScene(const std::vector<fs::path>& candidates) {
  std::string looked;
  for (const fs::path& p : candidates) {
    std::error_code error;
    if (fs::is_regular_file(p, error)) return p.lexically_normal();
    looked += (looked.empty() ? "" : ", ") + p.lexically_normal().string();
  }
  throw InputError(InputErrorKind::MissingData, "default_scene.json",
                   "the built-in scene is not installed; looked in " + looked +
                       " (or give one with --scene LAYOUT.json)");
}

fs::path findDefaultScene() {
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  // Without /proc (unusual) only the source tree is left to try.
  if (error) return findDefaultScene({fs::path(SDFSTREAM_SOURCE_SCENE)});
  return findDefaultScene(defaultSceneCandidates(exe));
}

}  // namespace sdfstream
