// The moving objects' host work per frame, without a GPU (sdfstream bench host): at each object
// count, the same spread objects and scripted motion as `sdfstream stress`, a synthetic stack of
// 4 cascades around them (1 m voxels, every page resident) and a sun, timing by part what
// GiSystem's recording does on the CPU for them -- the motion, the object frame (instances into
// stack space, changed boxes and wake bits), the card light slots and the shadow pages -- with
// nothing else on the machine's cores (stress's host figures share them with the Vulkan
// driver's threads, which on lavapipe run the GPU's work). Reports medians per part, µs per
// instance and the scaling exponents between counts.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace sdfstream::bench {

struct HostObjectsOptions {
  std::vector<std::uint32_t> objects = {100, 1000, 10000, 100000};
  int frames = 120;  // measured frames per count
  int warmup = 10;   // frames before measuring (the first adds every instance)
  std::uint32_t meshes = 2;
  std::uint64_t seed = 1;
  // Worker threads (TBB's parallelism); 0: every core. Runs at 1, 4, 16 ... show which parts
  // scale with the cores.
  int threads = 0;
  std::filesystem::path out = "out/bench/host";
};

// Writes OUT/summary.md and OUT/results.csv (replaced atomically) and prints the table.
void runHostObjectsBench(const HostObjectsOptions& options);

}  // namespace sdfstream::bench
