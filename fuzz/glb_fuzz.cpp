// Binary glTF (.glb): loadGltf (world/gltf_import.h) on arbitrary bytes: the GLB container
// (header, chunk lengths), the JSON chunk and the BIN chunk's accessors.
#include "fuzz/fuzz_support.h"
#include "world/gltf_import.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  const auto path = fuzz::writeFile("glb/input.glb", data, size);
  fuzz::expectOnlyInputError([&] {
    const TriangleScene scene = loadGltf(path);
    fuzz::checkScene(scene, /*positionsFinite=*/true);
    fuzz::sampleMaterials(scene);
  });
  return 0;
}
