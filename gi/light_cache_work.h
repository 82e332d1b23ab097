// The work of a full light-cache relight (diagnosis, `bench gi --gpu-table`): the surface cells
// that trace shadow rays, their sphere-tracing steps, and the warp-steps (a warp of 32 lanes
// runs as long as its longest ray) that the pass's lane mapping spends on them against other
// mappings. Counted by lightCacheWork (gi/light_cache.h) with the pass's own math.
#pragma once

#include <cstdint>
#include <vector>

namespace sdfstream {

struct LightCacheWork {
  std::uint64_t pages = 0;         // resident pages (all relit)
  std::uint64_t surfaceCells = 0;  // cells within the surface band: they evaluate the lights
  std::uint64_t shadowRays = 0;    // shadow marches (a surface cell facing a light, per light)
  std::uint64_t blockedRays = 0;   // of those, ended by a hit or out of steps
  std::uint64_t steps = 0;         // sphere-tracing steps of every march
  std::uint32_t maxCellSteps = 0;  // the most steps one cell took (all its lights)
  // Steps a surface cell takes, all lights together: median and 99th percentile.
  std::uint32_t medianCellSteps = 0, p99CellSteps = 0;
  // Surface cells and their steps by the cascade of their page.
  std::vector<std::uint64_t> surfaceCellsByCascade, stepsByCascade;
  // Warp-steps: Σ over warps of the longest lane's steps, when the surface cells are handed to
  // lanes as light_cache.comp does (per page, 64 lanes in two warps, in cell order), as one list
  // over all pages (page after page, 32 a warp), and the floor (steps / 32).
  std::uint64_t warpStepsPerPage = 0, warpStepsOneList = 0, warpStepsFloor = 0;
};

}  // namespace sdfstream
