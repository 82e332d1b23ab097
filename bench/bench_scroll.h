// `sdfstream bench scroll`: what a one-brick camera move costs against rebuilding every cascade
// from scratch, measured in the same run on the same world and the same (warm) tile cache.
// The streaming goal: a scroll ≥ 20× cheaper than a rebuild, in time and in bytes uploaded. Writes
// results.csv (every move and rebuild) and summary.md.
#pragma once

#include <filesystem>
#include <optional>

#include "gpu/context.h"

namespace sdfstream::bench {

struct ScrollBenchOptions {
  std::filesystem::path world;  // a world pack
  std::filesystem::path out = "out/bench/scroll";
  int moves = 16;  // one-brick moves along +x
  int cascades = 6;
  std::optional<gpu::ContextOptions> device;  // none: CPU only (no GPU upload measured)
};

// Returns 0. Throws InputError for a bad pack, std::runtime_error when the cascades never settle.
int runScrollBench(const ScrollBenchOptions& options);

}  // namespace sdfstream::bench
