#include "gi/object_frame.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include "core/stopwatch.h"

namespace sdfstream {
namespace gs = gpu_shared;

ObjectAtlasData buildObjectAtlas(const ObjectLibrary& library) {
  ObjectAtlasData atlas;
  for (std::uint32_t m = 0; m < library.size(); ++m) {
    const ObjectSdf& sdf = library.mesh(m);
    gs::ObjectMeshGpu rec{};
    rec.dimsOffset = glm::uvec4(sdf.dims, std::uint32_t(atlas.distance.size()));
    rec.gridMin = glm::vec4(sdf.gridMin, sdf.voxel);
    atlas.meshes.push_back(rec);
    atlas.distance.insert(atlas.distance.end(), sdf.distance.begin(), sdf.distance.end());
    for (std::size_t i = 0; i < sdf.distance.size(); ++i)
      atlas.material.emplace_back(sdf.albedo[i], sdf.emission[i]);
  }
  return atlas;
}

gs::ObjectInstanceGpu instanceInStack(const ObjectSdf& mesh, std::uint32_t meshIndex,
                                      const glm::dmat4& worldFromObject,
                                      const CascadeStackImage& stack) {
  // stack = (world - cascade0MinWorld) / voxelSize0; object = gridMin + voxel · grid.
  const double inv = 1.0 / stack.voxelSize0;
  glm::dmat4 stackFromWorld(inv);
  stackFromWorld[3] = glm::dvec4(-stack.cascade0MinWorld * inv, 1.0);
  glm::dmat4 objectFromGrid(double(mesh.voxel));
  objectFromGrid[3] = glm::dvec4(glm::dvec3(mesh.gridMin), 1.0);
  const glm::dmat4 stackFromGrid = stackFromWorld * worldFromObject * objectFromGrid;
  const glm::dmat4 gridFromStack = glm::inverse(stackFromGrid);

  gs::ObjectInstanceGpu g{};
  for (int r = 0; r < 3; ++r) {
    g.stackFromGrid[r] = glm::vec4(stackFromGrid[0][r], stackFromGrid[1][r], stackFromGrid[2][r],
                                   stackFromGrid[3][r]);
    g.gridFromStack[r] = glm::vec4(gridFromStack[0][r], gridFromStack[1][r], gridFromStack[2][r],
                                   gridFromStack[3][r]);
  }
  // Columns are orthogonal (rotation × diagonal scale), so the smallest singular value is the
  // shortest column and the OBB's half axes are the columns times half the grid extent.
  const glm::dvec3 hi = glm::dvec3(mesh.dims) - 1.0;
  double stepScale = 1e30, radius2 = 0.0;
  for (int j = 0; j < 3; ++j) {
    const double len = glm::length(glm::dvec3(stackFromGrid[j]));
    stepScale = std::min(stepScale, len);
    radius2 += (len * hi[j] * 0.5) * (len * hi[j] * 0.5);
  }
  // The AABB of the grid box [0, hi]: centre ± |M|·half (what its 8 corners' min and max are).
  const glm::dvec3 centre(stackFromGrid * glm::dvec4(0.5 * hi, 1.0));
  glm::dvec3 reach(0.0);
  for (int j = 0; j < 3; ++j) reach += glm::abs(glm::dvec3(stackFromGrid[j])) * (0.5 * hi[j]);
  g.boundsMin = glm::vec4(glm::vec3(centre - reach), float(stepScale));
  g.boundsMax = glm::vec4(glm::vec3(centre + reach), float(std::sqrt(radius2)));
  g.info = glm::uvec4(meshIndex, 0u, 0u, 0u);
  return g;
}

namespace {
// Inclusive region range of a stack AABB in region cascade c; false when it misses the grid.
bool regionRange(const gs::ObjectFrameGpu& f, std::uint32_t c, glm::vec3 bmin, glm::vec3 bmax,
                 glm::ivec3& lo, glm::ivec3& hi) {
  const glm::vec4 ro = f.regionOrigin[c];
  const glm::vec3 o(ro);
  const float inv = 1.0f / ro.w;  // region edges are powers of two: exact
  const glm::vec3 a = (bmin - o) * inv, b = (bmax - o) * inv;
  if (b.x < 0 || b.y < 0 || b.z < 0 || a.x > 8 || a.y > 8 || a.z > 8) return false;
  lo = glm::max(glm::ivec3(glm::floor(a)), glm::ivec3(0));
  hi = glm::min(glm::ivec3(glm::floor(b)), glm::ivec3(7));
  return lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z;
}

// The box in which a change can wake a probe, in stack space: the changed box itself and the
// cube of half-edge r / sqrt(wakeIrradianceChange) around its centre (r: its half-diagonal,
// which bounds the radius of the object at both ends of the move).
void wakeBox(const WorldBox& box, const CascadeStackImage& stack, float invSqrtChange,
             glm::vec3& lo, glm::vec3& hi) {
  const glm::vec3 a = stack.toStack(box.min), b = stack.toStack(box.max);
  const glm::vec3 centre = 0.5f * (a + b);
  const float reach = 0.5f * glm::length(b - a) * invSqrtChange;
  lo = glm::min(a, centre - reach);
  hi = glm::max(b, centre + reach);
}

// Sets the wake bit of sub-cell (x, y, z) (cascade sub-cell coordinates, 0..63) in its region.
inline void setWakeRow(gs::ObjectRegionGpu* regions, int rx, int y, int z, std::uint32_t row) {
  gs::ObjectRegionGpu& region = regions[rx + 8 * (y / 8 + 8 * (z / 8))];
  const int sy = y % 8, sz = z % 8;
  region.wake[sy / 4 + 2 * sz] |= row << (8 * (sy % 4));
}

// Rows of 8 sub-cells a range spans (the cost of marking it row by row).
std::uint64_t wakeRows(const ObjectFrameData::SubCellRange& r) {
  if (r.empty()) return 0;
  return std::uint64_t(r.hi.z - r.lo.z + 1) * std::uint64_t(r.hi.y - r.lo.y + 1) *
         std::uint64_t(r.hi.x / 8 - r.lo.x / 8 + 1);
}

// Row by row, parallel over the slabs of regions along z: each task owns its regions, so no
// atomics. Cost: the rows the boxes span, so for a few boxes.
void markWakeRowsInSlab(std::uint32_t c, int slab, std::uint32_t cascades,
                        const ObjectFrameData& in, gs::ObjectRegionGpu* regions) {
  const int zLo = slab * int(gs::kSubCellsPerAxis);
  const int zHi = zLo + int(gs::kSubCellsPerAxis) - 1;
  for (std::size_t k = 0; k < in.changedBoxes.size(); ++k) {
    const ObjectFrameData::SubCellRange& r = in.wakeRanges[k * cascades + c];
    if (r.empty()) continue;
    const int z0 = std::max(r.lo.z, zLo), z1 = std::min(r.hi.z, zHi);
    for (int z = z0; z <= z1; ++z)
      for (int y = r.lo.y; y <= r.hi.y; ++y)
        for (int rx = r.lo.x / 8; rx <= r.hi.x / 8; ++rx) {
          const int x0 = std::max(r.lo.x - rx * 8, 0), x1 = std::min(r.hi.x - rx * 8, 7);
          setWakeRow(regions, rx, y, z, ((2u << x1) - 1u) & ~((1u << x0) - 1u));
        }
  }
}

// Through a grid of counts: each box adds +-1 at the 8 corners of its range (inclusion-exclusion),
// three prefix sums turn that into the number of boxes covering each sub-cell, and the covered
// ones become wake bits. Cost: 8 updates a box plus 3 passes over the cascade's 64^3 sub-cells,
// whatever the boxes' sizes (10,000 moving objects span ~5 x 10^5 rows).
void markWakeGrid(std::uint32_t c, std::uint32_t cascades, ObjectFrameData& out,
                  gs::ObjectRegionGpu* regions) {
  constexpr int kSubs = int(gs::kRegionsPerAxis * gs::kSubCellsPerAxis);  // 64 per axis
  std::vector<std::int32_t>& grid = out.wakeGrids[c];
  grid.assign(std::size_t(kSubs) * kSubs * kSubs, 0);
  const auto at = [](int x, int y, int z) { return std::size_t(x + kSubs * (y + kSubs * z)); };
  for (std::size_t k = 0; k < out.changedBoxes.size(); ++k) {
    const ObjectFrameData::SubCellRange& r = out.wakeRanges[k * cascades + c];
    if (r.empty()) continue;
    const glm::ivec3 corner[2] = {r.lo, r.hi + 1};
    for (int n = 0; n < 8; ++n) {
      const int x = corner[n & 1].x, y = corner[(n >> 1) & 1].y, z = corner[n >> 2].z;
      if (x >= kSubs || y >= kSubs || z >= kSubs) continue;  // past the grid: sums never reach it
      grid[at(x, y, z)] += (std::popcount(unsigned(n)) & 1) ? -1 : 1;
    }
  }
  tbb::parallel_for(0, kSubs, [&](int z) {  // along x, then y, within each z plane
    for (int y = 0; y < kSubs; ++y)
      for (int x = 1; x < kSubs; ++x) grid[at(x, y, z)] += grid[at(x - 1, y, z)];
    for (int y = 1; y < kSubs; ++y)
      for (int x = 0; x < kSubs; ++x) grid[at(x, y, z)] += grid[at(x, y - 1, z)];
  });
  tbb::parallel_for(0, kSubs, [&](int y) {  // along z, then the bits of this row of sub-cells
    for (int z = 1; z < kSubs; ++z)
      for (int x = 0; x < kSubs; ++x) grid[at(x, y, z)] += grid[at(x, y, z - 1)];
  });
  tbb::parallel_for(0, int(gs::kRegionsPerAxis), [&](int slab) {  // each task owns its regions
    for (int z = slab * 8; z < slab * 8 + 8; ++z)
      for (int y = 0; y < kSubs; ++y)
        for (int rx = 0; rx < int(gs::kRegionsPerAxis); ++rx) {
          std::uint32_t row = 0;
          for (int x = 0; x < 8; ++x) row |= grid[at(rx * 8 + x, y, z)] > 0 ? 1u << x : 0u;
          if (row) setWakeRow(regions, rx, y, z, row);
        }
  });
}

// Sets the wake bits (and the moved flag) of every region sub-cell a changed box's wake box
// touches. Each box's sub-cell range per cascade is computed once, in parallel; then per cascade
// the cheaper of marking rows (few or small boxes) and a grid of counts (many).
void markWakeSubCells(const gs::ObjectFrameGpu& f, std::uint32_t cascades,
                      const CascadeStackImage& stack, const ObjectSceneSettings& settings,
                      ObjectFrameData& out) {
  using Range = ObjectFrameData::SubCellRange;
  constexpr int kSubs = int(gs::kRegionsPerAxis * gs::kSubCellsPerAxis);  // 64 per axis
  const std::size_t boxes = out.changedBoxes.size();
  out.movedRegions = 0;
  if (boxes == 0 || cascades == 0) return;
  const float invSqrtChange =
      1.0f / std::sqrt(std::clamp(settings.wakeIrradianceChange, 1e-4f, 1.0f));
  out.wakeRanges.resize(boxes * cascades);
  std::array<std::atomic<std::uint64_t>, gs::kMaxRegionCascades> rows{};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, boxes, 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      std::array<std::uint64_t, gs::kMaxRegionCascades> local{};
                      for (std::size_t k = range.begin(); k != range.end(); ++k) {
                        glm::vec3 lo, hi;
                        wakeBox(out.changedBoxes[k], stack, invSqrtChange, lo, hi);
                        for (std::uint32_t c = 0; c < cascades; ++c) {
                          const glm::vec4 ro = f.regionOrigin[c];
                          const float inv = float(gs::kSubCellsPerAxis) / ro.w;  // exact
                          const glm::vec3 a = (lo - glm::vec3(ro)) * inv;
                          const glm::vec3 b = (hi - glm::vec3(ro)) * inv;
                          Range& r = out.wakeRanges[k * cascades + c];
                          r.lo = glm::max(glm::ivec3(glm::floor(a)), glm::ivec3(0));
                          r.hi = glm::min(glm::ivec3(glm::floor(b)), glm::ivec3(kSubs - 1));
                          if (glm::any(glm::lessThan(b, glm::vec3(0.0f))) ||
                              glm::any(glm::greaterThan(a, glm::vec3(float(kSubs)))))
                            r.hi = glm::ivec3(-1);
                          local[c] += wakeRows(r);
                        }
                      }
                      for (std::uint32_t c = 0; c < cascades; ++c) rows[c] += local[c];
                    });
  // Both ways set the same bits; the grid's fixed cost pays off from wakeGridFromRows rows.
  std::vector<int> rowTasks;  // (cascade, slab) pairs marked row by row
  std::vector<std::uint32_t> gridCascades;
  for (std::uint32_t c = 0; c < cascades; ++c) {
    if (rows[c] == 0) continue;
    if (rows[c] >= settings.wakeGridFromRows) {
      gridCascades.push_back(c);
      if (out.wakeGrids.size() <= c) out.wakeGrids.resize(c + 1);
    } else {
      for (int slab = 0; slab < int(gs::kRegionsPerAxis); ++slab)
        rowTasks.push_back(int(c) * int(gs::kRegionsPerAxis) + slab);
    }
  }
  tbb::parallel_invoke(
      [&] {
        tbb::parallel_for(std::size_t(0), rowTasks.size(), [&](std::size_t t) {
          const std::uint32_t c = std::uint32_t(rowTasks[t]) / gs::kRegionsPerAxis;
          markWakeRowsInSlab(c, rowTasks[t] % int(gs::kRegionsPerAxis), cascades, out,
                             out.regions.data() + c * gs::kRegionsPerCascade);
        });
      },
      [&] {
        tbb::parallel_for(std::size_t(0), gridCascades.size(), [&](std::size_t i) {
          const std::uint32_t c = gridCascades[i];
          markWakeGrid(c, cascades, out, out.regions.data() + c * gs::kRegionsPerCascade);
        });
      });
  std::uint32_t moved = 0;
  for (gs::ObjectRegionGpu& region : out.regions) {
    std::uint32_t any = 0;
    for (std::uint32_t w : region.wake) any |= w;
    region.moved = any != 0u ? 1u : 0u;
    moved += region.moved;
  }
  out.movedRegions = moved;
}
}  // namespace

void buildObjectFrame(const ObjectLibrary& library, const InstanceSet& instances,
                      const CascadeStackImage& stack, const ObjectSceneSettings& settings,
                      ObjectFrameData& out) {
  const std::uint32_t cascades = std::min<std::uint32_t>(
      {settings.regionCascades, gs::kMaxRegionCascades, std::uint32_t(stack.params.size())});
  out.frame = gs::ObjectFrameGpu{};
  gs::ObjectFrameGpu& f = out.frame;
  f.counts =
      glm::uvec4(std::uint32_t(instances.size()), cascades, 0u, std::uint32_t(library.size()));
  for (std::uint32_t c = 0; c < cascades; ++c) {
    const glm::vec4 os = stack.params[c].offsetScale;
    f.regionOrigin[c] = glm::vec4(os.x, os.y, os.z, float(gs::kRegionCells) * os.w);
  }
  f.params = glm::vec4(settings.sizeRule, settings.hitEpsilon, float(settings.maxSteps), 0.0f);
  out.regions.assign(std::size_t(cascades) * gs::kRegionsPerCascade, gs::ObjectRegionGpu{});

  // The instances in stack space, in parallel (a 4×4 inverse each), with what the frame sums
  // over them: the list capacity, the cascades listing anything, the box around them all.
  const auto start = std::chrono::steady_clock::now();
  const std::span<const Instance> all = instances.instances();
  for (const Instance& inst : all) library.mesh(inst.mesh);  // unknown mesh: throws here
  out.instances.resize(all.size());
  struct Totals {
    std::uint64_t capacity = 0;
    std::uint32_t cascadeMask = 0, moved = 0;
    glm::vec3 lo{1e30f}, hi{-1e30f};  // empty until an instance widens it
  };
  const Totals totals = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, all.size(), 256), Totals{},
      [&](const tbb::blocked_range<std::size_t>& range, Totals t) {
        for (std::size_t k = range.begin(); k != range.end(); ++k) {
          const Instance& inst = all[k];
          gs::ObjectInstanceGpu g =
              instanceInStack(library.mesh(inst.mesh), inst.mesh, inst.pose.matrix(), stack);
          g.info.y = inst.movedThisFrame ? gs::kObjectFlagMoved : 0u;
          g.info.z = inst.id;
          t.moved += inst.movedThisFrame ? 1u : 0u;
          for (std::uint32_t c = 0; c < cascades; ++c) {
            if (c > 0 && g.boundsMax.w < settings.sizeRule * f.regionOrigin[c].w / 16.0f) continue;
            glm::ivec3 lo, hi;
            if (!regionRange(f, c, glm::vec3(g.boundsMin), glm::vec3(g.boundsMax), lo, hi))
              continue;
            const glm::ivec3 ext = hi - lo + 1;
            t.capacity += std::uint64_t(ext.x) * ext.y * ext.z;
            t.cascadeMask |= 1u << c;
          }
          out.instances[k] = g;
          t.lo = glm::min(t.lo, glm::vec3(g.boundsMin));
          t.hi = glm::max(t.hi, glm::vec3(g.boundsMax));
        }
        return t;
      },
      [](Totals a, const Totals& b) {
        a.capacity += b.capacity;
        a.cascadeMask |= b.cascadeMask;
        a.moved += b.moved;
        a.lo = glm::min(a.lo, b.lo);
        a.hi = glm::max(a.hi, b.hi);
        return a;
      });
  out.cascadeMask = totals.cascadeMask;
  out.movedInstances = totals.moved;
  f.boundsMin = glm::vec4(totals.lo, 0.0f);
  f.boundsMax = glm::vec4(totals.hi, 0.0f);
  const auto instancesDone = std::chrono::steady_clock::now();
  out.instancesMs = millisecondsSince(start);

  // Where probes wake: sub-cells near something that moved, appeared or vanished (old and new
  // poses as one box each), within the distance at which it can still change a probe's
  // irradiance by wakeIrradianceChange (ObjectSceneSettings).
  instances.changedBounds(library, out.changedBoxes);
  markWakeSubCells(f, cascades, stack, settings, out);
  out.wakeMs = millisecondsSince(instancesDone);
  // Slack for the GPU rounding a boundary differently from the host (the scan clamps anyway).
  out.listCapacity = std::uint32_t(totals.capacity + totals.capacity / 8 + 64);
  f.counts.z = out.listCapacity;
}

ObjectFrameData buildObjectFrame(const ObjectLibrary& library, const InstanceSet& instances,
                                 const CascadeStackImage& stack,
                                 const ObjectSceneSettings& settings) {
  ObjectFrameData out;
  buildObjectFrame(library, instances, stack, settings, out);
  return out;
}

}  // namespace sdfstream
