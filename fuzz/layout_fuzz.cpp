// Scene layouts: parseLayout (world/scene_layout.h) on arbitrary JSON bytes. parseLayout only
// checks that asset and heightmap files exist, so the scratch directory holds a few empty files
// under the names the seeds use; the fuzzer can then reach every key's validation, not only
// MissingData.
#include "fuzz/fuzz_support.h"
#include "world/scene_layout.h"

namespace {

void makeReferencedFiles() {
  for (const char* name : {"a.obj", "b.glb", "c.gltf", "h.png"})
    sdfstream::fuzz::writeFile(std::filesystem::path("layout") / name, "", 0);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  makeReferencedFiles();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  const auto path = fuzz::writeFile("layout/layout.json", data, size);
  fuzz::expectOnlyInputError([&] {
    const ParsedLayout layout = parseLayout(path);
    // Boxes are checked for finiteness where they become geometry (mesh_to_sdf), not here.
    fuzz::checkScene(layout.boxes, /*positionsFinite=*/false);
    for (const LayoutAsset& asset : layout.assets) {
      fuzz::contract(!asset.key.empty(), "every asset has its key for error messages");
      for (const LayoutPlacement& p : asset.placements)
        fuzz::contract(std::isfinite(p.translation.x) && std::isfinite(p.scale.x),
                       "finite placement");
    }
    if (layout.terrain)
      fuzz::contract(layout.terrain->metresPerPixel > 0.0 && layout.terrain->heightScale >= 0.0,
                     "terrain metresPerPixel > 0, heightScale >= 0");
  });
  return 0;
}
