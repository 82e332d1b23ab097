// objectShadowPages (gi/light_cache.h): the pages whose direct light a moving object may have
// changed, so the light cache relights only where objects moved.
//
// Cost. Thousands of objects move at once, so the work must not be boxes × pages swept. Under the
// sun every box's shadow is found at once through a page-resolution shadow map per cascade (the
// changed boxes' nearest depth per light-space cell), which each of the cascade's 4,096 pages then
// looks up: O(boxes + pages) per cascade and sun. Point and spot lights, whose shadows diverge,
// sweep each box away from the light in segments. Cascades are independent and run in parallel,
// and so do chunks of boxes within a cascade.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "gi/light_cache.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream {
namespace gs = gpu_shared;

namespace {
constexpr int kPagesPerAxis = 16;  // a cascade is 16³ pages of 8³ voxels
// Shadow-map cells per page edge: finer cells follow a shadow's outline more closely (fewer
// pages relit for nothing) at 4x the cells per doubling.
constexpr float kShadowCellsPerPage = 4.0f;
constexpr int kCellsPerAxis = kPagesPerAxis * int(kShadowCellsPerPage);
// Boxes are split into at most kMaxTasks chunks of at least kMinBoxesPerTask per cascade, each
// thread keeping its own cell bits or shadow map, merged after: the merge is serial per
// cascade, so with every core taking a chunk it would cost (cores x the map) -- as much as the
// work split -- on a 16-core host. 4 chunks x 4 cascades fill 16 cores.
constexpr std::size_t kMinBoxesPerTask = 1024;
constexpr std::size_t kMaxTasks = 4;
tbb::blocked_range<std::size_t> boxChunks(std::size_t boxes) {
  return {0, boxes, std::max(kMinBoxesPerTask, (boxes + kMaxTasks - 1) / kMaxTasks)};
}

struct Box {
  glm::vec3 lo, hi;
};

glm::vec3 corner(const Box& b, int k) {
  return glm::vec3((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z);
}

bool contains(const Box& b, glm::vec3 p) {
  return glm::all(glm::greaterThanEqual(p, b.lo)) && glm::all(glm::lessThanEqual(p, b.hi));
}

bool isSun(const gs::GpuLight& light) {
  return std::uint32_t(light.positionType.w + 0.5f) == gs::kLightSun;
}

// One cascade's page grid in stack space, and its marks (indexed by toroidal page entry).
struct CascadePages {
  glm::vec3 origin;  // stack position of page (0, 0, 0) of the window
  float edge;        // page edge in stack voxels
  glm::uvec3 toroidal;
  std::uint8_t* marked;            // kCascadePageCount entries
  const std::uint32_t* pageTable;  // the cascade's kCascadePageCount entries

  std::uint32_t entry(glm::ivec3 p) const {
    return ((std::uint32_t(p.x) + toroidal.x) & 15u) +
           16u * (((std::uint32_t(p.y) + toroidal.y) & 15u) +
                  16u * ((std::uint32_t(p.z) + toroidal.z) & 15u));
  }
  // Tasks of one cascade mark pages concurrently: a relaxed store per mark (the value is all
  // that matters, read after the tasks join).
  void markPage(glm::ivec3 p) const {
    std::atomic_ref<std::uint8_t>(marked[entry(p)]).store(1, std::memory_order_relaxed);
  }
  bool resident(glm::ivec3 p) const { return (pageTable[entry(p)] & gs::kPageResidentBit) != 0; }
  // Every page the box overlaps (faces included).
  void markBox(const Box& b) const {
    const glm::vec3 lo = (b.lo - origin) / edge, hi = (b.hi - origin) / edge;
    if (hi.x < 0 || hi.y < 0 || hi.z < 0 || lo.x > kPagesPerAxis || lo.y > kPagesPerAxis ||
        lo.z > kPagesPerAxis)
      return;
    const glm::ivec3 a = glm::clamp(glm::ivec3(glm::floor(lo)), glm::ivec3(0), glm::ivec3(15));
    const glm::ivec3 z = glm::clamp(glm::ivec3(glm::floor(hi)), glm::ivec3(0), glm::ivec3(15));
    for (int pz = a.z; pz <= z.z; ++pz)
      for (int py = a.y; py <= z.y; ++py)
        for (int px = a.x; px <= z.x; ++px) markPage({px, py, pz});
  }
};

// Marks the pages the boxes overlap (the objects' own surfaces, what they cover) and returns the
// boxes as the cascade's shadow map sees them, fewer: a box at most half a shadow cell wide grows
// to the cells (a quarter page each, inside one page) it touches, and each such cell is kept
// once; larger boxes and boxes outside the window stay as they are. Growing a box only adds
// shadow, so this stays conservative, and in coarse cascades thousands of small objects share a
// few hundred cells. Parallel over chunks of boxes, each thread with its own cell bits, ORed
// after.
struct Casters {
  std::vector<std::uint64_t> cells;  // kCellsPerAxis^3 bits (x fastest), empty: none
  std::vector<Box> boxes;            // kept as they are
};

std::vector<Box> markBoxesAndGatherCasters(const CascadePages& pages, std::span<const Box> boxes) {
  const float cell = pages.edge / kShadowCellsPerPage;
  const float invCell = 1.0f / cell;
  constexpr std::size_t kCellWords =
      std::size_t(kCellsPerAxis) * kCellsPerAxis * kCellsPerAxis / 64;
  // Per thread (a reduction passing these by value would copy them for every chunk of boxes).
  tbb::combinable<Casters> perThread;
  tbb::parallel_for(
      boxChunks(boxes.size()), [&](const tbb::blocked_range<std::size_t>& range) {
        Casters& local = perThread.local();
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const Box& b = boxes[i];
          const glm::vec3 lo = (b.lo - pages.origin) * invCell,
                          hi = (b.hi - pages.origin) * invCell;
          const bool small = glm::all(glm::lessThanEqual(hi - lo, glm::vec3(0.5f)));
          const bool inside = glm::all(glm::greaterThanEqual(lo, glm::vec3(0.0f))) &&
                              glm::all(glm::lessThan(hi, glm::vec3(float(kCellsPerAxis))));
          if (!small || !inside) {
            pages.markBox(b);
            local.boxes.push_back(b);
            continue;
          }
          if (local.cells.empty()) local.cells.assign(kCellWords, 0);
          // A box ending exactly on a cell face stays in the cell below it (cells are closed).
          const glm::ivec3 a(glm::floor(lo)), z = glm::max(a, glm::ivec3(glm::ceil(hi)) - 1);
          for (int cz = a.z; cz <= z.z; ++cz)
            for (int cy = a.y; cy <= z.y; ++cy)
              for (int cx = a.x; cx <= z.x; ++cx) {
                const std::size_t bit =
                    std::size_t(cx) +
                    std::size_t(kCellsPerAxis) * (cy + std::size_t(kCellsPerAxis) * cz);
                local.cells[bit / 64] |= std::uint64_t(1) << (bit % 64);
              }
        }
      });
  std::vector<Box> out;
  std::vector<std::uint64_t> cells;
  perThread.combine_each([&](const Casters& local) {
    out.insert(out.end(), local.boxes.begin(), local.boxes.end());
    if (local.cells.empty()) return;
    if (cells.empty()) cells.assign(kCellWords, 0);
    for (std::size_t w = 0; w < kCellWords; ++w) cells[w] |= local.cells[w];
  });
  if (cells.empty()) return out;
  // Each set cell becomes a caster box and marks its page: in parallel over runs of words, each
  // run's boxes appended after in run order (in coarse cascades thousands of cells are set).
  constexpr std::size_t kWordRuns = 16;
  std::array<std::vector<Box>, kWordRuns> runs;
  tbb::parallel_for(std::size_t(0), kWordRuns, [&](std::size_t run) {
    for (std::size_t w = run * kCellWords / kWordRuns; w < (run + 1) * kCellWords / kWordRuns; ++w)
      for (std::uint64_t bits = cells[w]; bits != 0; bits &= bits - 1) {
        const int bit = int(w * 64) + std::countr_zero(bits);
        const glm::ivec3 c(bit % kCellsPerAxis, bit / kCellsPerAxis % kCellsPerAxis,
                           bit / (kCellsPerAxis * kCellsPerAxis));
        pages.markPage(c / int(kShadowCellsPerPage));
        const glm::vec3 lo = pages.origin + glm::vec3(c) * cell;
        runs[run].push_back({lo, lo + glm::vec3(cell)});
      }
  });
  for (const std::vector<Box>& run : runs) out.insert(out.end(), run.begin(), run.end());
  return out;
}

// The shadows of every box under a sun shining along `away` (unit, away from the light), as a
// shadow map of the cascade: light-space cells a quarter of a page edge wide over the cascade's
// projection, each holding the nearest depth (along `away`) of the boxes whose
// projected rectangle touches it. A page is marked when a cell under its own projected rectangle
// holds a depth no farther than the page's far side. Conservative: a point x of a box shadows
// a point x + s·away (s >= 0) of the page; both project to one cell, whose depth is at most
// depth(x) <= depth(x + s·away) <= the page's far depth.
void markSunShadows(const CascadePages& pages, std::span<const Box> boxes, glm::vec3 away) {
  // A light-space basis: `away` and two unit vectors across it.
  const glm::vec3 helper = std::abs(away.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  const glm::vec3 t1 = glm::normalize(glm::cross(away, helper));
  const glm::vec3 t2 = glm::cross(away, t1);
  const glm::vec3 a1 = glm::abs(t1), a2 = glm::abs(t2), a0 = glm::abs(away);
  struct Footprint {
    glm::vec2 lo, hi;
    float nearDepth, farDepth;
  };
  // A box's projection from its centre and half extents: |t|·h is the half width along t.
  auto project = [&](glm::vec3 centre, glm::vec3 half) {
    const glm::vec2 c(glm::dot(centre, t1), glm::dot(centre, t2));
    const glm::vec2 r(glm::dot(half, a1), glm::dot(half, a2));
    const float d = glm::dot(centre, away), dr = glm::dot(half, a0);
    return Footprint{c - r, c + r, d - dr, d + dr};
  };
  const glm::vec3 windowHalf(0.5f * float(kPagesPerAxis) * pages.edge);
  const Footprint cascade = project(pages.origin + windowHalf, windowHalf);
  const float cell = pages.edge / kShadowCellsPerPage;
  const glm::ivec2 cells =
      glm::max(glm::ivec2(glm::ceil((cascade.hi - cascade.lo) / cell)), glm::ivec2(1));
  // Inclusive cell range of a footprint; false when it misses the map.
  auto cellRange = [&](const Footprint& f, glm::ivec2& a, glm::ivec2& z) {
    if (f.hi.x < cascade.lo.x || f.hi.y < cascade.lo.y || f.lo.x > cascade.hi.x ||
        f.lo.y > cascade.hi.y)
      return false;
    a = glm::clamp(glm::ivec2(glm::floor((f.lo - cascade.lo) / cell)), glm::ivec2(0), cells - 1);
    z = glm::clamp(glm::ivec2(glm::floor((f.hi - cascade.lo) / cell)), glm::ivec2(0), cells - 1);
    return true;
  };
  // Parallel over chunks of boxes, each thread with its own map (empty until a box lands),
  // merged by the minimum.
  const std::size_t mapCells = std::size_t(cells.x) * std::size_t(cells.y);
  tbb::combinable<std::vector<float>> perThread;
  tbb::parallel_for(boxChunks(boxes.size()), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<float>& local = perThread.local();
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      const Box& b = boxes[i];
      const Footprint f = project(0.5f * (b.lo + b.hi), 0.5f * (b.hi - b.lo));
      glm::ivec2 a, z;
      // A box past the cascade's far side shadows nothing of it.
      if (f.nearDepth > cascade.farDepth || !cellRange(f, a, z)) continue;
      if (local.empty()) local.assign(mapCells, 1e30f);
      for (int y = a.y; y <= z.y; ++y)
        for (int x = a.x; x <= z.x; ++x) {
          float& d = local[std::size_t(x) + std::size_t(cells.x) * std::size_t(y)];
          d = std::min(d, f.nearDepth);
        }
    }
  });
  std::vector<float> nearest;
  perThread.combine_each([&](const std::vector<float>& local) {
    if (local.empty()) return;
    if (nearest.empty()) {
      nearest = local;
      return;
    }
    for (std::size_t i = 0; i < mapCells; ++i) nearest[i] = std::min(nearest[i], local[i]);
  });
  if (nearest.empty()) return;
  // A summed-area table of the cells some box reaches: a page whose footprint holds none is
  // passed over in four reads instead of a scan of its ~50 cells (with few movers, most pages).
  const std::size_t w = std::size_t(cells.x) + 1;
  std::vector<std::uint32_t> reached(w * (std::size_t(cells.y) + 1), 0u);
  for (int y = 0; y < cells.y; ++y)
    for (int x = 0; x < cells.x; ++x)
      reached[std::size_t(x + 1) + w * std::size_t(y + 1)] =
          (nearest[std::size_t(x) + std::size_t(cells.x) * std::size_t(y)] < 1e30f ? 1u : 0u) +
          reached[std::size_t(x) + w * std::size_t(y + 1)] +
          reached[std::size_t(x + 1) + w * std::size_t(y)] -
          reached[std::size_t(x) + w * std::size_t(y)];
  auto anyReached = [&](glm::ivec2 a, glm::ivec2 z) {
    const std::size_t x0 = std::size_t(a.x), y0 = std::size_t(a.y);
    const std::size_t x1 = std::size_t(z.x) + 1, y1 = std::size_t(z.y) + 1;
    return reached[x1 + w * y1] + reached[x0 + w * y0] !=
           reached[x0 + w * y1] + reached[x1 + w * y0];
  };
  // Only resident pages can be relit, so only they are looked up; slabs of pages in parallel
  // (each page's mark is its own byte).
  const glm::vec3 pageHalf(0.5f * pages.edge);
  tbb::parallel_for(0, kPagesPerAxis, [&](int pz) {
    for (int py = 0; py < kPagesPerAxis; ++py)
      for (int px = 0; px < kPagesPerAxis; ++px) {
        if (!pages.resident({px, py, pz})) continue;
        const glm::vec3 centre = pages.origin + (glm::vec3(px, py, pz) + 0.5f) * pages.edge;
        const Footprint f = project(centre, pageHalf);
        glm::ivec2 a, z;
        if (!cellRange(f, a, z) || !anyReached(a, z)) continue;
        bool shadowed = false;
        for (int y = a.y; y <= z.y && !shadowed; ++y)
          for (int x = a.x; x <= z.x && !shadowed; ++x)
            shadowed =
                nearest[std::size_t(x) + std::size_t(cells.x) * std::size_t(y)] <= f.farDepth;
        if (shadowed) pages.markPage({px, py, pz});
      }
  });
}

// The part of the box's shadow between distances s0 and s1 from a point light: every corner
// moved s0 and s1 stack voxels away from the light, as one box. Marking the shadow piece by
// piece follows a slanted shadow closely, where one box around the whole sweep would cover a
// quarter of a cascade.
Box pointShadowSegment(const Box& b, glm::vec3 lightPos, float s0, float s1) {
  Box out{glm::vec3(1e30f), glm::vec3(-1e30f)};
  for (int k = 0; k < 8; ++k) {
    const glm::vec3 p = corner(b, k);
    const glm::vec3 away = p - lightPos;
    const glm::vec3 u = away / std::max(glm::length(away), 1e-6f);
    for (float sv : {s0, s1}) {
      out.lo = glm::min(out.lo, p + u * sv);
      out.hi = glm::max(out.hi, p + u * sv);
    }
  }
  return out;
}

// A point or spot light: each box swept away from it until `reach`, in segments a page long
// near the box that grow by a quarter of their distance after (the shadow widens with distance
// anyway). A light inside a box may change anything in the cascade.
void markPointShadows(const CascadePages& pages, std::span<const Box> boxes, glm::vec3 lightPos,
                      float reach) {
  const Box window{pages.origin, pages.origin + glm::vec3(float(kPagesPerAxis) * pages.edge)};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, boxes.size(), kMinBoxesPerTask / 4),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const Box& b = boxes[i];
                        if (contains(b, lightPos)) {
                          pages.markBox(window);
                          continue;
                        }
                        for (float s0 = 0.0f; s0 < reach;) {
                          const float s1 = std::min(reach, s0 + std::max(pages.edge, 0.25f * s0));
                          const Box seg = pointShadowSegment(b, lightPos, s0, s1);
                          if (glm::all(glm::lessThanEqual(seg.lo, window.hi)) &&
                              glm::all(glm::greaterThanEqual(seg.hi, window.lo)))
                            pages.markBox(seg);
                          s0 = s1;
                        }
                      }
                    });
}
}  // namespace

std::vector<std::uint32_t> objectShadowPages(const CascadeStackImage& stack,
                                             std::span<const WorldBox> changed,
                                             std::span<const gs::GpuLight> lights) {
  std::vector<std::uint32_t> pages;
  if (changed.empty() || stack.params.empty()) return pages;
  const float reach = 128.0f * stack.params.back().offsetScale.w * 1.7320508f;
  std::vector<Box> boxes(changed.size());
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, changed.size(), 1024),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i)
          boxes[i] = Box{stack.toStack(changed[i].min), stack.toStack(changed[i].max)};
      });

  const std::size_t cascades = stack.params.size();
  std::vector<std::uint8_t> marked(cascades * gs::kCascadePageCount, 0);
  std::vector<CascadePages> grids;
  for (std::size_t c = 0; c < cascades; ++c) {
    const gs::CascadeTraceParams& p = stack.params[c];
    grids.push_back({glm::vec3(p.offsetScale), 8.0f * p.offsetScale.w, glm::uvec3(p.toroidal),
                     &marked[c * gs::kCascadePageCount], &stack.pageTables[p.toroidal.w]});
  }
  // Cascades are independent; inside one, the boxes (gathering casters, building the shadow map,
  // sweeping from point lights) and the shadow map's page lookups run in parallel too: splitting
  // by cascade alone leaves all but 4 cores idle and one cascade's boxes on a single core.
  tbb::parallel_for(std::size_t(0), cascades, [&](std::size_t c) {
    const std::vector<Box> casters = markBoxesAndGatherCasters(grids[c], boxes);
    for (const gs::GpuLight& l : lights) {
      if (l.shape.w <= 0.5f) continue;  // casts no shadow
      if (isSun(l)) {
        markSunShadows(grids[c], casters, -glm::normalize(glm::vec3(l.direction)));
      } else {
        markPointShadows(grids[c], boxes, glm::vec3(l.positionType), reach);
      }
    }
  });
  for (std::uint32_t c = 0; c < cascades; ++c) {
    const std::uint32_t base = stack.params[c].toroidal.w;
    for (std::uint32_t e = 0; e < gs::kCascadePageCount; ++e)
      if (marked[c * gs::kCascadePageCount + e] &&
          (stack.pageTables[base + e] & gs::kPageResidentBit))
        pages.push_back(base + e);
  }
  return pages;  // ascending: cascades in order, entries in order
}

}  // namespace sdfstream
