#include "gi/object_frame.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
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
  // stack = (world - cascade0MinWorld) / voxelSize0; object = gridMin + voxel · grid. So
  // stackFromGrid = [A | t]: A = worldFromObject's 3×3 part × voxel / voxelSize0 and
  // t = (worldFromObject · gridMin - cascade0MinWorld) / voxelSize0.
  const double inv = 1.0 / stack.voxelSize0;
  const glm::dvec3 translation =
      (glm::dvec3(worldFromObject * glm::dvec4(glm::dvec3(mesh.gridMin), 1.0)) -
       stack.cascade0MinWorld) *
      inv;
  std::array<glm::dvec3, 3> column;
  for (int j = 0; j < 3; ++j)
    column[j] = glm::dvec3(worldFromObject[j]) * (double(mesh.voxel) * inv);
  // A's columns are orthogonal (rotation × diagonal scale), so its inverse is its transpose with
  // row j divided by |column j|², and the inverse's translation follows: no general 4×4 inverse
  // per instance per frame. The smallest singular value is the shortest column, and the OBB's
  // half axes are the columns times half the grid extent.
  const glm::dvec3 hi = glm::dvec3(mesh.dims) - 1.0;
  gs::ObjectInstanceGpu g{};
  double stepScale = 1e30, radius2 = 0.0;
  glm::dvec3 centre = translation, reach(0.0);
  for (int j = 0; j < 3; ++j) {
    const double len2 = glm::dot(column[j], column[j]), len = std::sqrt(len2);
    const glm::dvec3 row = column[j] / len2;  // row j of A's inverse
    g.gridFromStack[j] = glm::vec4(glm::vec3(row), float(-glm::dot(row, translation)));
    stepScale = std::min(stepScale, len);
    radius2 += (len * hi[j] * 0.5) * (len * hi[j] * 0.5);
    // The AABB of the grid box [0, hi]: centre ± |A|·half (its 8 corners' min and max).
    centre += column[j] * (0.5 * hi[j]);
    reach += glm::abs(column[j]) * (0.5 * hi[j]);
  }
  for (int r = 0; r < 3; ++r)
    g.stackFromGrid[r] = glm::vec4(column[0][r], column[1][r], column[2][r], translation[r]);
  g.boundsMin = glm::vec4(glm::vec3(centre - reach), float(stepScale));
  g.boundsMax = glm::vec4(glm::vec3(centre + reach), float(std::sqrt(radius2)));
  g.info = glm::uvec4(meshIndex, 0u, 0u, 0u);
  return g;
}

namespace {
// The object-size-to-voxel rule (ObjectSceneSettings::sizeRule): an object of this bounding
// radius (stack voxels) is listed in region cascade c, so that cascade's probes can see it.
bool listedIn(const gs::ObjectFrameGpu& f, std::uint32_t c, float radius, float sizeRule) {
  return c == 0 || radius >= sizeRule * f.regionOrigin[c].w / float(gs::kRegionCells);
}

// Sub-cells (object_layout.h) of cascade c's region grid that instance g's AABB touches: every
// region's share of them together, an upper bound of its sub-cell list entries there.
std::uint64_t subCellVolume(const gs::ObjectFrameGpu& f, std::uint32_t c,
                            const gs::ObjectInstanceGpu& g) {
  const glm::vec4 ro = f.regionOrigin[c];
  const float perSub = float(gs::kSubCellsPerAxis) / ro.w;
  const glm::ivec3 last(int(gs::kRegionsPerAxis * gs::kSubCellsPerAxis) - 1);
  const glm::ivec3 lo =
      glm::clamp(glm::ivec3(glm::floor((glm::vec3(g.boundsMin) - glm::vec3(ro)) * perSub)),
                 glm::ivec3(0), last);
  const glm::ivec3 hi =
      glm::clamp(glm::ivec3(glm::floor((glm::vec3(g.boundsMax) - glm::vec3(ro)) * perSub)),
                 glm::ivec3(0), last);
  const glm::ivec3 ext = glm::max(hi - lo + 1, glm::ivec3(0));
  return std::uint64_t(ext.x) * ext.y * ext.z;
}

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

// The ball in which a change can wake a probe, in stack space: radius r /
// sqrt(wakeIrradianceChange) around the changed box's centre (r: its half-diagonal, which bounds
// the radius of the object at both ends of the move; the ball holds the box, as the change is at
// most 1). A probe beyond it sees the object cover less than wakeIrradianceChange of its
// hemisphere, so a cube around the ball (the first rule) woke nearly twice the probes (its volume
// over the ball's, 6 / pi) for nothing. Returns the changed box's half-diagonal (stack voxels), for
// the size rule.
float wakeBall(const WorldBox& box, const CascadeStackImage& stack, float invSqrtChange,
               glm::vec3& centre, float& reach) {
  const glm::vec3 a = stack.toStack(box.min), b = stack.toStack(box.max);
  centre = 0.5f * (a + b);
  const float halfDiagonal = 0.5f * glm::length(b - a);
  // The box's corners lie on the ball at a change of 1: a hair more keeps them inside.
  reach = halfDiagonal * invSqrtChange * (1.0f + 1e-5f);
  return halfDiagonal;
}

// A cascade's wake sub-cells as 64 x 64 rows of 64 bits (bit x of row y + 64 z): a box sets a
// contiguous run of bits in each row it spans, one OR each, so the cost is the (y, z) rows the
// boxes span, whatever their width in x.
constexpr int kSubCells = int(gs::kRegionsPerAxis * gs::kSubCellsPerAxis);  // 64 per axis
static_assert(kSubCells == 64, "a row of sub-cells is one 64-bit word");
using WakeRows = std::vector<std::uint64_t>;  // kSubCells^2 rows

// Distance from v to the sub-cell interval [i, i + 1] along one axis.
float outside(float v, int i) { return std::max(0.0f, std::max(float(i) - v, v - float(i + 1))); }

// Sets the bits of the sub-cells the ball touches: per row, the run its chord there covers.
void markWakeRange(const ObjectFrameData::SubCellRange& r, WakeRows& rows) {
  if (r.empty()) return;
  const float r2 = r.radius * r.radius;
  for (int z = r.lo.z; z <= r.hi.z; ++z) {
    const float dz = outside(r.centre.z, z);
    for (int y = r.lo.y; y <= r.hi.y; ++y) {
      const float dy = outside(r.centre.y, y);
      const float left = r2 - dy * dy - dz * dz;
      if (left < 0.0f) continue;
      const float chord = std::sqrt(left);
      const int lo = std::max(r.lo.x, int(std::floor(r.centre.x - chord)));
      const int hi = std::min(r.hi.x, int(std::floor(r.centre.x + chord)));
      if (lo > hi) continue;
      const std::uint64_t bits = (~std::uint64_t(0) >> (63 - hi)) & (~std::uint64_t(0) << lo);
      rows[std::size_t(y + kSubCells * z)] |= bits;
    }
  }
}

// The rows into the regions' wake words (region.wake[sy / 4 + 2 sz], byte sy % 4 = the row of
// 8 sub-cells at (sy, sz) in the region) and moved flags; returns the regions moved. Only rows
// with a bit set are visited, so few movers cost few rows.
std::uint32_t wakeRowsToRegions(const WakeRows& rows, gs::ObjectRegionGpu* regions) {
  for (int z = 0; z < kSubCells; ++z)
    for (int y = 0; y < kSubCells; ++y) {
      const std::uint64_t row = rows[std::size_t(y + kSubCells * z)];
      if (row == 0) continue;
      const int sy = y % 8, sz = z % 8;
      for (int rx = 0; rx < 8; ++rx) {
        const std::uint32_t byte = std::uint32_t(row >> (8 * rx)) & 0xFFu;
        if (byte == 0) continue;
        gs::ObjectRegionGpu& region = regions[rx + 8 * (y / 8 + 8 * (z / 8))];
        region.wake[sy / 4 + 2 * sz] |= byte << (8 * (sy % 4));
        region.moved = 1u;
      }
    }
  std::uint32_t moved = 0;
  for (std::uint32_t r = 0; r < gs::kRegionsPerCascade; ++r) moved += regions[r].moved;
  return moved;
}

// Sets the wake bits (and the moved flag) of every region sub-cell a changed box's wake ball
// touches, in the cascades that list an object of the box's size (sizeRule, with the box's
// half-diagonal for the radius: never smaller than the object's): a coarser cascade's probes
// never see the object, so its move cannot change their irradiance. Per cascade, the boxes'
// sub-cell ranges are ORed into rows in parallel chunks of boxes (each thread its own 32 KiB of
// rows, merged after), then spread into the regions.
void markWakeSubCells(const gs::ObjectFrameGpu& f, std::uint32_t cascades,
                      const CascadeStackImage& stack, const ObjectSceneSettings& settings,
                      ObjectFrameData& out) {
  using Range = ObjectFrameData::SubCellRange;
  const std::size_t boxes = out.changedBoxes.size();
  out.movedRegions = 0;
  if (boxes == 0 || cascades == 0) return;
  const float invSqrtChange =
      1.0f / std::sqrt(std::clamp(settings.wakeIrradianceChange, 1e-4f, 1.0f));
  out.wakeRanges.resize(boxes * cascades);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, boxes, 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k != range.end(); ++k) {
                        glm::vec3 centre;
                        float reach;
                        const float radius =
                            wakeBall(out.changedBoxes[k], stack, invSqrtChange, centre, reach);
                        const glm::vec3 lo = centre - reach, hi = centre + reach;
                        for (std::uint32_t c = 0; c < cascades; ++c) {
                          Range& r = out.wakeRanges[k * cascades + c];
                          r.lo = glm::ivec3(0);
                          r.hi = glm::ivec3(-1);
                          // A cascade that would not list the object wakes nothing: checked
                          // first, it spares the range's arithmetic.
                          if (!listedIn(f, c, radius, settings.sizeRule)) continue;
                          const glm::vec4 ro = f.regionOrigin[c];
                          const float inv = float(gs::kSubCellsPerAxis) / ro.w;  // exact
                          const glm::vec3 a = (lo - glm::vec3(ro)) * inv;
                          const glm::vec3 b = (hi - glm::vec3(ro)) * inv;
                          if (glm::any(glm::lessThan(b, glm::vec3(0.0f))) ||
                              glm::any(glm::greaterThan(a, glm::vec3(float(kSubCells)))))
                            continue;
                          r.lo = glm::max(glm::ivec3(glm::floor(a)), glm::ivec3(0));
                          r.hi = glm::min(glm::ivec3(glm::floor(b)), glm::ivec3(kSubCells - 1));
                          r.centre = (centre - glm::vec3(ro)) * inv;
                          r.radius = reach * inv;
                        }
                      }
                    });
  std::array<std::uint32_t, gs::kMaxRegionCascades> moved{};
  tbb::parallel_for(std::uint32_t(0), cascades, [&](std::uint32_t c) {
    // Rows per thread, ORed after (a reduction passing the rows by value would copy them for
    // every chunk of boxes).
    tbb::combinable<WakeRows> perThread(
        [] { return WakeRows(std::size_t(kSubCells) * kSubCells); });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, boxes, 1024),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        WakeRows& local = perThread.local();
                        for (std::size_t k = range.begin(); k != range.end(); ++k)
                          markWakeRange(out.wakeRanges[k * cascades + c], local);
                      });
    WakeRows rows(std::size_t(kSubCells) * kSubCells, 0);
    perThread.combine_each([&](const WakeRows& local) {
      for (std::size_t i = 0; i < rows.size(); ++i) rows[i] |= local[i];
    });
    moved[c] = wakeRowsToRegions(rows, out.regions.data() + c * gs::kRegionsPerCascade);
  });
  for (std::uint32_t c = 0; c < cascades; ++c) out.movedRegions += moved[c];
}
}  // namespace

void buildObjectFrame(const ObjectLibrary& library, const InstanceSet& instances,
                      const CascadeStackImage& stack, const ObjectSceneSettings& settings,
                      ObjectFrameData& out, const std::function<void()>& changedBoxesReady) {
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
  const std::span<const Instance> all = instances.instances();
  for (const Instance& inst : all) library.mesh(inst.mesh);  // unknown mesh: throws here
  out.instances.resize(all.size());
  struct Totals {
    std::uint64_t capacity = 0, subCapacity = 0;
    std::uint32_t cascadeMask = 0, moved = 0;
    glm::vec3 lo{1e30f}, hi{-1e30f};  // empty until an instance widens it
    // Per region, the instances whose AABB range touches it: the regions occupied (the mean
    // list length's denominator), and each list's slots when the frame has no sub-cell lists
    // (object_layout.h, ObjectRegionGpu::slots).
    std::array<std::uint32_t, gs::kMaxRegionCascades * gs::kRegionsPerCascade> ranges{};
  };
  auto instancesInStack = [&] {
    return tbb::parallel_reduce(
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
              if (!listedIn(f, c, g.boundsMax.w, settings.sizeRule)) continue;
              glm::ivec3 lo, hi;
              if (!regionRange(f, c, glm::vec3(g.boundsMin), glm::vec3(g.boundsMax), lo, hi))
                continue;
              const glm::ivec3 ext = hi - lo + 1;
              const std::uint64_t regions = std::uint64_t(ext.x) * ext.y * ext.z;
              t.capacity += regions;
              t.subCapacity += std::min(subCellVolume(f, c, g), regions * gs::kSubListMaxCells);
              t.cascadeMask |= 1u << c;
              for (int z = lo.z; z <= hi.z; ++z)
                for (int y = lo.y; y <= hi.y; ++y)
                  for (int x = lo.x; x <= hi.x; ++x) {
                    const std::uint32_t r =
                        c * gs::kRegionsPerCascade + std::uint32_t(x + 8 * (y + 8 * z));
                    ++t.ranges[r];
                  }
            }
            out.instances[k] = g;
            t.lo = glm::min(t.lo, glm::vec3(g.boundsMin));
            t.hi = glm::max(t.hi, glm::vec3(g.boundsMax));
          }
          return t;
        },
        [](Totals a, const Totals& b) {
          a.capacity += b.capacity;
          a.subCapacity += b.subCapacity;
          a.cascadeMask |= b.cascadeMask;
          a.moved += b.moved;
          a.lo = glm::min(a.lo, b.lo);
          a.hi = glm::max(a.hi, b.hi);
          for (std::size_t r = 0; r < a.ranges.size(); ++r) a.ranges[r] += b.ranges[r];
          return a;
        });
  };
  // Where probes wake: sub-cells near something that moved, appeared or vanished (old and new
  // poses as one box each), within the distance at which it can still change a probe's
  // irradiance by wakeIrradianceChange (ObjectSceneSettings). Independent of the instances'
  // stack-space form (both only read the set; they write different parts of `out`), so the two
  // run side by side and share the cores.
  Totals totals;
  tbb::parallel_invoke(
      [&] {
        const auto start = std::chrono::steady_clock::now();
        totals = instancesInStack();
        out.instancesMs = millisecondsSince(start);
      },
      [&] {
        const auto start = std::chrono::steady_clock::now();
        instances.changedBounds(library, out.changedBoxes);
        if (changedBoxesReady) changedBoxesReady();
        markWakeSubCells(f, cascades, stack, settings, out);
        out.wakeMs = millisecondsSince(start);
      });
  out.cascadeMask = totals.cascadeMask;
  out.occupiedRegions = std::uint32_t(std::count_if(totals.ranges.begin(), totals.ranges.end(),
                                                    [](std::uint32_t n) { return n > 0; }));
  out.movedInstances = totals.moved;
  f.boundsMin = glm::vec4(totals.lo, 0.0f);
  f.boundsMax = glm::vec4(totals.hi, 0.0f);
  const bool longLists = double(totals.capacity) >=
                         double(settings.subListMinMeanEntries) * double(out.occupiedRegions);
  out.subListCapacity =
      longLists ? std::uint32_t(std::min<std::uint64_t>(
                      totals.subCapacity + totals.subCapacity / 8 + 64, settings.maxSubListEntries))
                : 0u;
  if (out.subListCapacity > 0) {
    // The GPU's scan places the lists. Slack for it rounding a boundary differently from the
    // host (it clamps anyway).
    out.listCapacity = std::uint32_t(totals.capacity + totals.capacity / 8 + 64);
  } else {
    // No sub-cell lists: each region's slots and start from its AABB ranges, so the GPU fills
    // the lists and the occupancy in one pass (no count, rank or scan; object_regions.comp,
    // phase 6).
    std::uint32_t start = 0;
    for (std::size_t r = 0; r < out.regions.size(); ++r) {
      gs::ObjectRegionGpu& region = out.regions[r];
      region.start = start;
      region.slots = totals.ranges[r];
      region.subBase = gs::kNoSubLists;
      start += totals.ranges[r];
    }
    out.listCapacity = std::max(start, 1u);
  }
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
