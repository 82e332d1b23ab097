// World pack manifests: readManifest (world/pack.h) on arbitrary manifest.json bytes.
#include "fuzz/fuzz_support.h"
#include "world/pack.h"
#include "world/pack_format.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  const auto path = fuzz::writeFile("pack/manifest.json", data, size);
  fuzz::expectOnlyInputError([&] {
    const PackManifest m = readManifest(path.parent_path());
    fuzz::contract(pack_format::specProblem(m.spec).empty(), "the spec follows partition.h");
    for (std::size_t i = 0; i < m.tiles.size(); ++i) {
      const TileEntry& t = m.tiles[i];
      fuzz::contract(t.file == pack_format::tileFileName(t.coord), "tile file named by coord");
      fuzz::contract(t.bricksPerLod.size() == std::size_t(m.spec.lodCount), "one count per LOD");
      fuzz::contract(i == 0 || brickCoordLess(m.tiles[i - 1].coord, t.coord), "tiles sorted");
    }
  });
  return 0;
}
