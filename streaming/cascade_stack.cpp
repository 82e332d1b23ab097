#include "streaming/cascade_stack.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <set>

namespace sdfstream {
namespace {
constexpr int kPages = int(layout::kCascadePages);
constexpr std::size_t kBrickBytes =
    4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);

int floorDiv(int a, int b) { return (a >= 0) ? a / b : -((-a + b - 1) / b); }
int wrap16(int v) { return v & 15; }  // two's complement: correct for negatives too

const Brick* findBrick(const TileLod& lod, glm::ivec3 coord) {
  auto it = std::lower_bound(lod.bricks.begin(), lod.bricks.end(), coord,
                             [](const Brick& b, const glm::ivec3& c) { return brickCoordLess(b.coord, c); });
  return (it != lod.bricks.end() && it->coord == coord) ? &*it : nullptr;
}
}  // namespace

CascadeStack::CascadeStack(const TileStore& store, TileLoader& loader, StreamingOptions options)
    : store_(store), loader_(loader), options_(options) {
  assert(options_.cascades >= 1 && options_.cascades <= 8);
  options_.cascades = std::min(options_.cascades, store_.spec().lodCount);
  cascades_.resize(options_.cascades);
  for (Cascade& c : cascades_) {
    c.entries.assign(layout::kCascadePageCount, layout::kPageMissing);
    c.bricks.assign(layout::kCascadePageCount, glm::ivec3(0));
    c.pending.assign(layout::kCascadePageCount, 0);
  }
  distance_.assign(std::size_t(options_.atlasSlots) * layout::kBrickDistanceWords, 0u);
  albedo_.assign(std::size_t(options_.atlasSlots) * layout::kBrickMaterialCount, 0u);
  emission_.assign(std::size_t(options_.atlasSlots) * layout::kBrickMaterialCount, 0u);
  // Pop from the back: slot 0 is handed out first.
  for (std::uint32_t s = options_.atlasSlots; s-- > 0;) freeSlots_.push_back(s);
}

double CascadeStack::voxelSize(int c) const { return store_.spec().lodVoxelSize(c); }

void CascadeStack::limitAtlasSlots(std::uint32_t slots) {
  if (slots >= options_.atlasSlots) return;
  for (Cascade& c : cascades_)
    for (std::uint32_t page = 0; page < c.entries.size(); ++page) {
      std::uint32_t& e = c.entries[page];
      if (!(e & layout::kPageResidentBit) || (e & layout::kPagePayloadMask) < slots) continue;
      e = layout::kPageMissing;
      if (!c.pending[page]) {  // asked for again: into a slot below, or counted atlas-full
        c.pending[page] = 1;
        ++c.pendingCount;
      }
    }
  freeSlots_.erase(std::remove_if(freeSlots_.begin(), freeSlots_.end(),
                                  [&](std::uint32_t s) { return s >= slots; }),
                   freeSlots_.end());
  std::erase_if(dirtySlots_, [&](std::uint32_t s) { return s >= slots; });
  options_.atlasSlots = slots;
}

std::size_t CascadeStack::atlasBytes() const { return std::size_t(options_.atlasSlots) * kBrickBytes; }

std::vector<std::uint32_t> CascadeStack::takeDirtySlots() {
  std::vector<std::uint32_t> out;
  out.swap(dirtySlots_);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

void CascadeStack::releasePage(Cascade& cascade, std::uint32_t page) {
  std::uint32_t e = cascade.entries[page];
  if (e & layout::kPageResidentBit) freeSlots_.push_back(e & layout::kPagePayloadMask);
  cascade.entries[page] = layout::kPageMissing;
}

void CascadeStack::scroll(int c, glm::ivec3 newOrigin, CascadeFrameStats& stats) {
  Cascade& cascade = cascades_[c];
  if (cascade.placed && cascade.origin == newOrigin) return;
  // Each toroidal slot s holds the unique brick b of the window with b ≡ s (mod 16). Only slots
  // whose brick changed are touched: a one-brick move changes one 16×16 slab.
  for (int z = 0; z < kPages; ++z)
    for (int y = 0; y < kPages; ++y)
      for (int x = 0; x < kPages; ++x) {
        glm::ivec3 b(newOrigin.x + wrap16(x - newOrigin.x), newOrigin.y + wrap16(y - newOrigin.y),
                     newOrigin.z + wrap16(z - newOrigin.z));
        std::uint32_t page = std::uint32_t(x + kPages * (y + kPages * z));
        if (cascade.placed && cascade.bricks[page] == b) continue;
        releasePage(cascade, page);
        cascade.bricks[page] = b;
        if (!cascade.pending[page]) {
          cascade.pending[page] = 1;
          ++cascade.pendingCount;
        }
        ++stats.pagesChanged;
      }
  cascade.origin = newOrigin;
  cascade.placed = true;
}

StreamFrameStats CascadeStack::update(const glm::dvec3& cameraWorld,
                                      const glm::dvec3& viewDirection) {
  const PartitionSpec& spec = store_.spec();
  StreamFrameStats stats;
  stats.cascades.resize(cascades_.size());

  struct Candidate {
    double priority;
    int cascade;
    std::uint32_t page;
  };
  std::vector<Candidate> candidates;
  for (int c = 0; c < cascadeCount(); ++c) {
    const double v = spec.lodVoxelSize(c);
    glm::dvec3 index = (cameraWorld - spec.origin) / v;
    glm::ivec3 cameraBrick(int(std::floor(index.x / 8.0)), int(std::floor(index.y / 8.0)),
                           int(std::floor(index.z / 8.0)));
    scroll(c, cameraBrick - glm::ivec3(kPages / 2), stats.cascades[c]);
    Cascade& cascade = cascades_[c];
    if (cascade.pendingCount == 0) continue;
    for (std::uint32_t page = 0; page < layout::kCascadePageCount; ++page) {
      if (!cascade.pending[page]) continue;
      glm::dvec3 centre = (glm::dvec3(cascade.bricks[page]) * 8.0 + 4.0) * v + spec.origin;
      // Finer cascades first, then nearer pages, pages in front of the camera before those behind
      // it: a page behind counts as up to twice as far.
      glm::dvec3 toPage = centre - cameraWorld;
      double distance = glm::length(toPage);
      double behind = distance > 0 ? 0.5 * (1.0 - glm::dot(toPage / distance, viewDirection)) : 0;
      candidates.push_back({c * 1e9 + distance * (1.0 + behind), c, page});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.priority < b.priority; });

  std::set<TileKey, TileKeyLess> wantedTiles;
  for (const Candidate& cand : candidates) {
    Cascade& cascade = cascades_[cand.cascade];
    glm::ivec3 brick = cascade.bricks[cand.page];
    const int n = spec.tileBricks(cand.cascade);
    glm::ivec3 tileCoord(floorDiv(brick.x, n), floorDiv(brick.y, n), floorDiv(brick.z, n));
    auto settle = [&](std::uint32_t entry) {
      cascade.entries[cand.page] = entry;
      cascade.pending[cand.page] = 0;
      --cascade.pendingCount;
    };
    if (!store_.hasTile(tileCoord)) {
      // No surface anywhere in that tile; neighbours may have some right at the border.
      settle(0u);
      continue;
    }
    const TileKey key{tileCoord, cand.cascade};  // cascade c reads LOD c
    if (stats.bytesUploaded + kBrickBytes > options_.uploadBytesPerFrame) {
      wantedTiles.insert(key);
      continue;  // over this frame's upload budget: stays missing, filled next frame
    }
    std::shared_ptr<const Tile> tile = loader_.acquire(key, cand.priority);
    if (!tile) {
      wantedTiles.insert(key);
      if (loader_.failed(key)) ++stats.failedPages;
      continue;
    }
    const TileLod& lod = tile->lods[cand.cascade];
    if (const Brick* b = findBrick(lod, brick)) {
      if (freeSlots_.empty()) {
        ++stats.atlasFullPages;
        continue;
      }
      std::uint32_t slot = freeSlots_.back();
      freeSlots_.pop_back();
      std::uint32_t* d = &distance_[std::size_t(slot) * layout::kBrickDistanceWords];
      std::fill(d, d + layout::kBrickDistanceWords, 0u);
      for (std::uint32_t s = 0; s < layout::kBrickSampleCount; ++s)
        d[s / 2] |= std::uint32_t(b->distance[s]) << (16 * (s & 1));
      std::copy(b->albedo.begin(), b->albedo.end(),
                albedo_.begin() + std::size_t(slot) * layout::kBrickMaterialCount);
      std::copy(b->emission.begin(), b->emission.end(),
                emission_.begin() + std::size_t(slot) * layout::kBrickMaterialCount);
      dirtySlots_.push_back(slot);
      stats.bytesUploaded += kBrickBytes;
      settle(layout::kPageResidentBit | slot);
    } else {
      glm::ivec3 local = brick - tileCoord * n;
      std::uint8_t k = lod.emptyDistance.empty()
                           ? 0
                           : lod.emptyDistance[std::size_t(local.x + n * (local.y + n * local.z))];
      settle(k == 0 ? 0u : std::uint32_t(k - 1) * layout::kBrickCells);
    }
  }
  loader_.retainOnly([&](const TileKey& k) { return wantedTiles.count(k) != 0; });

  for (int c = 0; c < cascadeCount(); ++c) {
    auto& cs = stats.cascades[c];
    for (std::uint32_t e : cascades_[c].entries) {
      if (e & layout::kPageResidentBit) ++cs.residentBricks;
      if (e == layout::kPageMissing) ++cs.missingPages;
    }
    cs.requiredBricks = cs.residentBricks + cs.missingPages;
    stats.missingPages += cs.missingPages;
  }
  stats.atlasSlotsUsed = options_.atlasSlots - std::uint32_t(freeSlots_.size());
  return stats;
}

bool CascadeStack::settled() const {
  for (const Cascade& c : cascades_)
    if (!c.placed || c.pendingCount) return false;
  return true;
}

CascadeStackImage CascadeStack::stackImage() const {
  const PartitionSpec& spec = store_.spec();
  CascadeStackImage img;
  img.distanceAtlas = &distance_;
  img.albedoAtlas = &albedo_;
  img.emissionAtlas = &emission_;
  img.voxelSize0 = spec.voxelSize;
  const glm::ivec3 min0 = cascades_[0].origin * int(layout::kBrickCells);  // LOD-0 cells
  img.cascade0MinWorld = spec.origin + glm::dvec3(min0) * spec.voxelSize;
  for (int c = 0; c < cascadeCount(); ++c) {
    img.pageTables.insert(img.pageTables.end(), cascades_[c].entries.begin(),
                          cascades_[c].entries.end());
    // Integer LOD-0 cell offsets: exact in float for any window within 2^24 cells of cascade 0.
    glm::ivec3 minC = cascades_[c].origin * int(layout::kBrickCells << c);
    gpu_shared::CascadeTraceParams p;
    p.offsetScale = glm::vec4(glm::vec3(minC - min0), float(1 << c));
    glm::ivec3 o = cascades_[c].origin;
    p.toroidal = glm::uvec4(std::uint32_t(o.x) & 15u, std::uint32_t(o.y) & 15u,
                            std::uint32_t(o.z) & 15u, std::uint32_t(c) * layout::kCascadePageCount);
    img.params.push_back(p);
    img.originBricks.push_back(o);
  }
  return img;
}

CascadeImage CascadeStack::cascadeImage(int c) const {
  CascadeImage img;
  img.voxelSize = voxelSize(c);
  img.worldOrigin = store_.spec().origin;
  img.originBrick = cascades_[c].origin;
  img.pageTable = cascades_[c].entries;
  img.distanceAtlas = distance_;
  img.albedoAtlas = albedo_;
  img.emissionAtlas = emission_;
  for (std::uint32_t e : img.pageTable) img.residentBricks += (e & layout::kPageResidentBit) ? 1 : 0;
  return img;
}

}  // namespace sdfstream
