// Wavefront OBJ: loadObj (world/obj_import.h) on arbitrary bytes.
#include "fuzz/fuzz_support.h"
#include "world/obj_import.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  const auto path = fuzz::writeFile("obj/input.obj", data, size);
  fuzz::expectOnlyInputError([&] {
    const TriangleScene scene = loadObj(path);
    fuzz::checkScene(scene, /*positionsFinite=*/true);
    fuzz::contract(!scene.triangles.empty(), "loadObj returns at least one triangle");
  });
  return 0;
}
