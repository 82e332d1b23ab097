// Heightmap PNGs: Heightfield::load (world/heightfield_source.h) on arbitrary bytes, then the
// queries a tile builder makes, so a decoded image of any size is also walked.
#include "fuzz/fuzz_support.h"
#include "world/heightfield_source.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  HeightfieldDesc desc;
  desc.png = fuzz::writeFile("heightmap/input.png", data, size);
  desc.metresPerPixel = 1.0;
  desc.heightScale = 10.0;
  fuzz::expectOnlyInputError([&] {
    const Heightfield field = Heightfield::load(desc);
    fuzz::contract(field.width() >= 2 && field.height() >= 2, "at least 2x2 pixels");
    const glm::dvec3 lo = field.boundsMin(), hi = field.boundsMax();
    const glm::dvec3 mid = 0.5 * (lo + hi);
    const double d = field.signedDistance(mid);
    const glm::dvec2 range = field.heightRange(lo.x, lo.z, hi.x, hi.z);
    fuzz::contract(std::isfinite(d) && range.x <= range.y, "finite distance, ordered range");
  });
  return 0;
}
