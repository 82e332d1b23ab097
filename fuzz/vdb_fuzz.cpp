// OpenVDB level sets: vdbToWorld (world/vdb_import.h) on arbitrary .vdb bytes. OpenVDB itself is
// not instrumented (a system library): its crashes still show, its out-of-bounds reads may not.
//
// A fixed 1 m override voxel makes every input take the resampling path (the seeds are 1 m
// spheres, so they resample 1:1), and the import limit is far below libFuzzer's malloc limit so
// an estimate that is honoured keeps allocations bounded; one that is not shows as an OOM.
#include <tbb/global_control.h>

#include "fuzz/fuzz_support.h"
#include "world/vdb_import.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // One worker thread: the fuzzer shares its machine and the seeds' grids are tiny.
  static auto* limit =
      new tbb::global_control(tbb::global_control::max_allowed_parallelism, 1);
  (void)limit;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  const auto path = fuzz::writeFile("vdb/input.vdb", data, size);
  ImportLimits limits;
  limits.maxBytes = 256ull << 20;
  fuzz::expectOnlyInputError([&] {
    const World world = vdbToWorld(path, /*voxelSizeOverride=*/1.0, limits);
    fuzz::contract(!world.bricks.empty(), "an imported world has bricks");
  });
  return 0;
}
