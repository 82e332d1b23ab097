// The object library's disk cache: parseObjectSdf (objects/object_cache.h) on arbitrary bytes.
// It reports bad bytes as nullopt with a reason, never by throwing, so here nothing may escape.
//
// The key and the trailing XXH3 cannot be forged by mutation: the harness passes the key the
// bytes carry and rewrites the checksum as serializeObjectSdf would, so the fields behind them
// are what gets fuzzed (the mismatch paths are covered by tests/objects).
#include <cstring>
#include <vector>

#include "core/hash.h"
#include "fuzz/fuzz_support.h"
#include "objects/object_cache.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  std::vector<std::uint8_t> bytes(data, data + size);
  std::uint64_t key = 0;
  if (bytes.size() >= 20) std::memcpy(&key, bytes.data() + 12, 8);  // u32 keyLo, u32 keyHi
  if (bytes.size() >= 8) {
    const std::uint64_t sum = checksum64(bytes.data(), bytes.size() - 8);
    std::memcpy(bytes.data() + bytes.size() - 8, &sum, 8);
  }
  std::string problem;
  const std::optional<ObjectSdf> sdf = parseObjectSdf(bytes, key, &problem);
  if (!sdf) {
    fuzz::contract(!problem.empty(), "a rejected file has a reason");
    return 0;
  }
  const std::size_t n = sdf->sampleCount();
  fuzz::contract(sdf->dims.x >= 2 && sdf->dims.y >= 2 && sdf->dims.z >= 2, "dims >= 2");
  fuzz::contract(sdf->distance.size() == n && sdf->albedo.size() == n && sdf->emission.size() == n,
                 "one value per sample");
  fuzz::contract(std::isfinite(sdf->voxel) && sdf->voxel > 0.0f, "finite positive voxel");
  return 0;
}
