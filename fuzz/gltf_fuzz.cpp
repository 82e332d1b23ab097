// glTF text (.gltf): loadGltf (world/gltf_import.h) on arbitrary bytes. External URIs resolve
// against the scratch directory, where nothing else lives, so they end as MissingData; embedded
// data: URIs (the seeds use them) are decoded.
#include "fuzz/fuzz_support.h"
#include "world/gltf_import.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  const auto path = fuzz::writeFile("gltf/input.gltf", data, size);
  fuzz::expectOnlyInputError([&] {
    const TriangleScene scene = loadGltf(path);
    fuzz::checkScene(scene, /*positionsFinite=*/true);
    fuzz::sampleMaterials(scene);
  });
  return 0;
}
