// The path tracer's irradiance cache (reference/irradiance_cache.h). Its parser is internal, so
// the path-based reader is fuzzed: the input is written where cachedIrradiance looks for the
// query's file, and cachedIrradiance either loads it or, when it is invalid, traces the (tiny)
// query again and rewrites it.
//
// The key (a hash of the scene and query) and the payload's XXH3 cannot be forged by mutation:
// the harness writes the query's key into any input long enough to hold one, and the payload
// checksum into an input of exactly the valid size, so the loading path is reached too.
#include <cstring>
#include <vector>

#include <tbb/global_control.h>

#include "core/hash.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/irradiance_scene.h"

namespace {

using namespace sdfstream;
using Query = fuzz::IrradianceQuery;

const Query& query() {
  // Never destroyed: Embree's device must not be torn down after TBB's at exit.
  static const Query* q = new Query;
  return *q;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // One worker thread: the fuzzer shares its machine, and a trace of two points needs no more.
  static auto* limit =
      new tbb::global_control(tbb::global_control::max_allowed_parallelism, 1);
  (void)limit;
  query();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Query& q = query();
  const std::filesystem::path dir = fuzz::scratchDir() / "irradiance";
  const std::uint64_t key =
      reference::irradianceCacheKey(*q.tracer, q.positions, q.normals, Query::kSamples, Query::kKind);
  std::vector<std::uint8_t> bytes(data, data + size);
  // Offsets from the layout in reference/irradiance_cache.h.
  constexpr std::size_t kHeader = 40, kRecord = 28;
  if (bytes.size() >= 24) std::memcpy(bytes.data() + 16, &key, 8);
  if (bytes.size() == kHeader + q.positions.size() * kRecord) {
    const std::uint64_t sum = checksum64(bytes.data() + kHeader, bytes.size() - kHeader);
    std::memcpy(bytes.data() + 32, &sum, 8);
  }
  const std::filesystem::path file = reference::irradianceCachePath(
      dir, *q.tracer, q.positions, q.normals, Query::kSamples, Query::kKind);
  fuzz::writeFile(file.lexically_relative(fuzz::scratchDir()), bytes.data(), bytes.size());
  fuzz::expectOnlyInputError([&] {
    reference::CacheOutcome outcome{};
    const auto estimates = reference::cachedIrradiance(dir, *q.tracer, q.positions, q.normals,
                                                       Query::kSamples, Query::kKind, &outcome);
    fuzz::contract(estimates.size() == q.positions.size(), "one estimate per query point");
    fuzz::contract(outcome != reference::CacheOutcome::Computed, "the file existed");
  });
  return 0;
}
