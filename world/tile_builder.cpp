#include "world/tile_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

#include <glm/gtc/packing.hpp>

#include "world/color_pack.h"

namespace sdfstream {
namespace {

constexpr int kCells = int(layout::kBrickCells);
constexpr int kSamples = int(layout::kBrickSamples);
constexpr float kBand = layout::kNarrowBand;
constexpr float kInf = std::numeric_limits<float>::infinity();
using Samples = std::array<float, layout::kBrickSampleCount>;

int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

using CellSources = std::array<const SdfSource*, layout::kBrickMaterialCount>;

struct Materials {
  std::array<std::uint32_t, layout::kBrickMaterialCount> albedo{}, emission{}, emitter{};
  std::array<float, layout::kBrickMaterialCount> distance;  // |d| of the chosen sample; inf: none
  CellSources source{};  // which source gave the cell its material (its emitter's owner)
};

// One LOD's bricks over the tile plus a margin. Bricks that are uniform (every sample +band, or
// every sample -band: far outside / deep inside) hold no array.
struct Region {
  glm::ivec3 lo{0};            // first brick (global LOD coords)
  int size = 0;                // bricks per edge
  std::vector<int> slot;       // size³: index into values, or -1 (uniform)
  std::vector<float> uniform;  // size³: the value of uniform bricks
  std::vector<Samples> values;
  std::vector<char> occupied;  // size³: some |d| < kBand

  int index(glm::ivec3 b) const {
    glm::ivec3 r = b - lo;
    if (r.x < 0 || r.y < 0 || r.z < 0 || r.x >= size || r.y >= size || r.z >= size) return -1;
    return r.x + size * (r.y + size * r.z);
  }
  glm::ivec3 brickAt(int i) const {
    return lo + glm::ivec3(i % size, i / size % size, i / (size * size));
  }
  // Sample s (global LOD index); +inf when outside the region (unknown).
  float sample(glm::ivec3 s) const {
    glm::ivec3 b(floorDiv(s.x, kCells), floorDiv(s.y, kCells), floorDiv(s.z, kCells));
    glm::ivec3 local = s - b * kCells;
    for (int a = 0; a < 3; ++a)  // the region's far apron lives in the last brick
      if (b[a] == lo[a] + size && local[a] == 0) b[a] -= 1, local[a] = kCells;
    const int i = index(b);
    if (i < 0) return kInf;
    return slot[std::size_t(i)] < 0
               ? uniform[std::size_t(i)]
               : values[std::size_t(slot[std::size_t(i)])]
                       [std::size_t(brickSampleIndex(local.x, local.y, local.z))];
  }
};

bool anyInBand(const Samples& s) {
  for (float d : s)
    if (std::abs(d) < kBand) return true;
  return false;
}

// Sources' brick ranges at one LOD: bounds grown by the band plus one brick; only those that
// reach the bricks [regionLo, regionHi] (a layout places thousands of sources, a tile sees a few).
struct SourceRange {
  const SdfSource* source;
  glm::ivec3 lo, hi;  // inclusive, LOD-l brick coords
};

std::vector<SourceRange> sourceRanges(const std::vector<const SdfSource*>& sources,
                                      const PartitionSpec& spec, int lod, glm::ivec3 regionLo,
                                      glm::ivec3 regionHi) {
  const double v = spec.lodVoxelSize(lod);
  const double grow = (kBand + kCells) * v;
  std::vector<SourceRange> out;
  for (const SdfSource* s : sources) {
    glm::dvec3 lo = (s->boundsMin() - grow - spec.origin) / (v * kCells);
    glm::dvec3 hi = (s->boundsMax() + grow - spec.origin) / (v * kCells);
    lo = glm::clamp(glm::floor(lo), -1e9, 1e9);
    hi = glm::clamp(glm::floor(hi), -1e9, 1e9);
    const SourceRange r{s, glm::ivec3(lo), glm::ivec3(hi)};
    if (!glm::any(glm::lessThan(r.hi, regionLo)) && !glm::any(glm::greaterThan(r.lo, regionHi)))
      out.push_back(r);
  }
  return out;
}

bool inRange(const SourceRange& r, glm::ivec3 b) {
  return !glm::any(glm::lessThan(b, r.lo)) && !glm::any(glm::greaterThan(b, r.hi));
}

bool inAnyRange(const std::vector<SourceRange>& ranges, glm::ivec3 b) {
  for (const SourceRange& r : ranges)
    if (inRange(r, b)) return true;
  return false;
}

// Samples the union of the sources for one brick (materials when wantMaterials; then `winners`,
// when given, gets the source each cell's material came from).
bool sampleUnion(const std::vector<SourceRange>& ranges, int lod, glm::ivec3 b, bool wantMaterials,
                 BrickSamples& out, CellSources* winners = nullptr) {
  out.distance.fill(kBand);
  out.albedo.fill(0);
  out.emission.fill(0);
  out.emitter.fill(0);
  out.materialDistance.fill(wantMaterials ? kInf : 0.0f);
  if (winners) winners->fill(nullptr);
  bool any = false;
  std::array<float, layout::kBrickMaterialCount> before;
  for (const SourceRange& r : ranges) {
    if (!inRange(r, b)) continue;
    if (winners) before = out.materialDistance;
    r.source->sampleBrick(lod, b, out);
    if (winners)
      for (std::size_t c = 0; c < before.size(); ++c)
        if (out.materialDistance[c] < before[c]) (*winners)[c] = r.source;
    any = true;
  }
  return any;
}

// Stores samples for region slot i: uniform when all are ±kBand alike.
void store(Region& region, int i, const Samples& s) {
  const float first = s[0];
  bool uniform = std::abs(first) >= kBand;
  for (std::size_t k = 1; uniform && k < s.size(); ++k) uniform = s[k] == first;
  region.occupied[std::size_t(i)] = anyInBand(s);
  if (uniform) {
    region.slot[std::size_t(i)] = -1;
    region.uniform[std::size_t(i)] = first;
  } else {
    region.slot[std::size_t(i)] = int(region.values.size());
    region.values.push_back(s);
  }
}

// Whether any fine brick under the window of coarse brick b's samples (fine samples 16b-1 ..
// 16b+17) holds something below the band: otherwise filterBrick changes nothing.
bool fineAnything(const Region& fine, glm::ivec3 b) {
  for (int z = -1; z <= 2; ++z)
    for (int y = -1; y <= 2; ++y)
      for (int x = -1; x <= 2; ++x) {
        const int i = fine.index(2 * b + glm::ivec3(x, y, z));
        if (i < 0) continue;
        if (fine.slot[std::size_t(i)] >= 0 || fine.uniform[std::size_t(i)] < kBand) return true;
      }
  return false;
}

// The conservative filter for coarse brick b (see tile_builder.h) into s; fine = LOD l-1.
void filterBrick(const Region& fine, glm::ivec3 b, Samples& s) {
  if (!fineAnything(fine, b)) return;
  constexpr int kW = 2 * kCells + 3;  // 19 fine samples per axis
  static thread_local std::vector<float> buf(kW * kW * kW);
  const glm::ivec3 base = 2 * kCells * b - 1;
  // Region::sample, separated per axis: which region brick (-1: outside) and which local sample
  // each of the 19 positions reads.
  int brickAt[3][kW], localAt[3][kW];
  for (int a = 0; a < 3; ++a)
    for (int x = 0; x < kW; ++x) {
      const int sa = base[a] + x;
      int bb = floorDiv(sa, kCells), local = sa - bb * kCells;
      if (bb == fine.lo[a] + fine.size && local == 0) bb -= 1, local = kCells;
      const int r = bb - fine.lo[a];
      brickAt[a][x] = r < 0 || r >= fine.size ? -1 : r;
      localAt[a][x] = local;
    }
  const int n = fine.size;
  for (int z = 0; z < kW; ++z)
    for (int y = 0; y < kW; ++y) {
      float* row = &buf[std::size_t(kW * (y + kW * z))];
      if (brickAt[2][z] < 0 || brickAt[1][y] < 0) {
        std::fill(row, row + kW, kInf);
        continue;
      }
      const int rowBase = n * (brickAt[1][y] + n * brickAt[2][z]);
      const int localBase = brickSampleIndex(0, localAt[1][y], localAt[2][z]);
      for (int x = 0; x < kW; ++x) {
        float f = kInf;
        if (brickAt[0][x] >= 0) {
          const std::size_t i = std::size_t(rowBase + brickAt[0][x]);
          const int sl = fine.slot[i];
          f = sl < 0 ? fine.uniform[i]
                     : fine.values[std::size_t(sl)][std::size_t(localBase + localAt[0][x])];
        }
        row[x] = f < kBand ? f : kInf;  // saturated: no part
      }
    }
  // The centre and its 6 face neighbours (reach one fine voxel = half a coarse voxel).
  for (int k = 0; k < kSamples; ++k)
    for (int j = 0; j < kSamples; ++j)
      for (int i = 0; i < kSamples; ++i) {
        const int c = (2 * i + 1) + kW * ((2 * j + 1) + kW * (2 * k + 1));
        float m = buf[std::size_t(c)];
        for (int step : {1, kW, kW * kW})
          m = std::min(m, std::min(buf[std::size_t(c - step)], buf[std::size_t(c + step)]));
        float& d = s[std::size_t(brickSampleIndex(i, j, k))];
        if (m < kInf) d = std::clamp(std::min(d, 0.5f * m), -kBand, kBand);
      }
}

// Chebyshev distance (in bricks) from every slot of the region to the nearest occupied slot,
// slots outside the region counting as occupied; clamped to 255.
std::vector<int> chebyshev(const Region& r) {
  const int n = r.size;
  constexpr int kBig = 1 << 20;
  std::vector<int> d(std::size_t(n) * n * n), tmp(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = r.occupied[i] ? 0 : kBig;
  // Chebyshev distance is separable: d(x) = min over y of max(|x-y|, d'(y)), one axis at a time.
  const int stride[3] = {1, n, n * n};
  for (int axis = 0; axis < 3; ++axis) {
    for (int i = 0; i < n * n * n; ++i) {
      const int coord = i / stride[axis] % n;
      const int lineStart = i - coord * stride[axis];
      int best = std::min(coord + 1, n - coord);  // the outside counts as occupied
      for (int k = 0; k < n; ++k)
        best = std::min(
            best, std::max(std::abs(k - coord), d[std::size_t(lineStart + k * stride[axis])]));
      tmp[std::size_t(i)] = best;
    }
    std::swap(d, tmp);
  }
  return d;
}

}  // namespace

Tile buildTile(const std::vector<const SdfSource*>& sources, const PartitionSpec& spec,
               glm::ivec3 tile) {
  Tile out;
  out.coord = tile;
  out.lods.resize(std::size_t(spec.lodCount));
  Region fine;
  std::vector<std::unique_ptr<Materials>> fineMaterials;  // per tile-own fine brick (or null)
  BrickSamples samples;
  CellSources winners;
  for (int lod = 0; lod < spec.lodCount; ++lod) {
    const int n = spec.tileBricks(lod);
    // Fine samples the coarser levels' tile bricks read, beyond this tile: 2^(L-1-l) - 1.
    const int exact = (1 << (spec.lodCount - 1 - lod)) - 1;
    const int margin = std::max(kEmptyMargin, (exact + kCells - 1) / kCells);
    Region region;
    region.lo = tile * n - margin;
    region.size = n + 2 * margin;
    const std::size_t slots = std::size_t(region.size) * region.size * region.size;
    region.slot.assign(slots, -1);
    region.uniform.assign(slots, kBand);
    region.occupied.assign(slots, 0);
    const std::vector<SourceRange> ranges =
        sourceRanges(sources, spec, lod, region.lo, region.lo + (region.size - 1));
    std::vector<std::unique_ptr<Materials>> materials(std::size_t(n) * n * n);
    auto ownIndex = [&](glm::ivec3 b) {
      glm::ivec3 r = b - tile * n;
      if (glm::any(glm::lessThan(r, glm::ivec3(0))) ||
          glm::any(glm::greaterThanEqual(r, glm::ivec3(n))))
        return -1;
      return r.x + n * (r.y + n * r.z);
    };

    for (int i = 0; i < int(slots); ++i) {
      const glm::ivec3 b = region.brickAt(i);
      const int own = ownIndex(b);
      const bool wantMaterials = lod == 0 && own >= 0;
      // No source near and nothing finer below the band: uniform +band, as the slot already is
      // (what sampling, filtering and store would give, without touching 729 samples).
      if (!inAnyRange(ranges, b) && (lod == 0 || !fineAnything(fine, b))) continue;
      sampleUnion(ranges, lod, b, wantMaterials, samples, wantMaterials ? &winners : nullptr);
      Samples s = samples.distance;
      if (lod > 0) filterBrick(fine, b, s);
      store(region, i, s);
      if (wantMaterials && region.occupied[std::size_t(i)]) {
        auto m = std::make_unique<Materials>();
        m->albedo = samples.albedo;
        m->emission = samples.emission;
        m->emitter = samples.emitter;
        m->source = winners;
        m->distance = samples.materialDistance;
        materials[std::size_t(own)] = std::move(m);
      }
    }

    // Coarse materials from the fine cells; sources at this LOD for cells with none.
    if (lod > 0) {
      const int fn = spec.tileBricks(lod - 1);
      for (int i = 0; i < int(slots); ++i) {
        const glm::ivec3 b = region.brickAt(i);
        const int own = ownIndex(b);
        if (own < 0 || !region.occupied[std::size_t(i)]) continue;
        auto m = std::make_unique<Materials>();
        m->distance.fill(kInf);
        bool missing = false;
        for (int c = 0; c < int(layout::kBrickMaterialCount); ++c) {
          const glm::ivec3 cell =
              b * kCells + glm::ivec3(c % kCells, c / kCells % kCells, c / (kCells * kCells));
          for (int k = 0; k < 8; ++k) {
            const glm::ivec3 f = 2 * cell + glm::ivec3(k & 1, k >> 1 & 1, k >> 2);
            const glm::ivec3 fb(floorDiv(f.x, kCells), floorDiv(f.y, kCells),
                                floorDiv(f.z, kCells));
            const glm::ivec3 fr = fb - tile * fn;  // always inside the fine tile
            const Materials* fm = fineMaterials[std::size_t(fr.x + fn * (fr.y + fn * fr.z))].get();
            if (!fm) continue;
            const glm::ivec3 fl = f - fb * kCells;
            const std::size_t fc = std::size_t(brickCellIndex(fl.x, fl.y, fl.z));
            const float d = 0.5f * fm->distance[fc];  // fine voxels → coarse voxels
            if (d < m->distance[std::size_t(c)]) {
              m->distance[std::size_t(c)] = d;
              m->albedo[std::size_t(c)] = fm->albedo[fc];
              m->emission[std::size_t(c)] = fm->emission[fc];
              m->emitter[std::size_t(c)] = fm->emitter[fc];
              m->source[std::size_t(c)] = fm->source[fc];
            }
          }
          missing = missing || m->distance[std::size_t(c)] == kInf;
        }
        // An inherited emitter's emission, scaled from the finer LOD's flux factor to this one's.
        for (std::size_t c = 0; c < layout::kBrickMaterialCount; ++c)
          if (m->emitter[c] != 0 && m->source[c] != nullptr) {
            const float ratio = m->source[c]->emissionRatio(lod, m->emitter[c]);
            if (ratio != 1.0f)
              m->emission[c] = packRgb9e5(gpu_shared::unpackRgb9e5(m->emission[c]) * ratio);
          }
        if (missing) {
          sampleUnion(ranges, lod, b, true, samples, &winners);
          for (std::size_t c = 0; c < layout::kBrickMaterialCount; ++c)
            if (m->distance[c] == kInf) {
              m->albedo[c] = samples.albedo[c];
              m->emission[c] = samples.emission[c];
              m->emitter[c] = samples.emitter[c];
              m->source[c] = winners[c];
              m->distance[c] = samples.materialDistance[c];
            }
        }
        materials[std::size_t(own)] = std::move(m);
      }
    }

    // Pack the tile's own bricks (region order is z, y, x: already sorted) and the empty data.
    TileLod& tl = out.lods[std::size_t(lod)];
    const std::vector<int> dist = chebyshev(region);
    tl.emptyDistance.resize(std::size_t(n) * n * n);
    for (int i = 0; i < int(slots); ++i) {
      const glm::ivec3 b = region.brickAt(i);
      const int own = ownIndex(b);
      if (own < 0) continue;
      tl.emptyDistance[std::size_t(own)] = std::uint8_t(std::min(dist[std::size_t(i)], 255));
      if (!region.occupied[std::size_t(i)]) continue;
      Brick brick;
      brick.coord = b;
      const int sl = region.slot[std::size_t(i)];
      for (std::size_t k = 0; k < layout::kBrickSampleCount; ++k)
        brick.distance[k] = std::uint16_t(glm::packHalf1x16(
            sl < 0 ? region.uniform[std::size_t(i)] : region.values[std::size_t(sl)][k]));
      if (const Materials* m = materials[std::size_t(own)].get()) {
        brick.albedo = m->albedo;
        brick.emission = m->emission;
      }
      tl.bricks.push_back(brick);
    }
    fine = std::move(region);
    fineMaterials = std::move(materials);
  }
  return out;
}

}  // namespace sdfstream
