#include "streaming/cascade.h"

#include <algorithm>
#include <cassert>
#include <cstring>

namespace sdfstream {
namespace {
constexpr int kPages = int(layout::kCascadePages);
constexpr std::uint32_t kFarBound = 1u << 20;  // "no surface in the window" (voxels)

int floorDiv(int a, int b) { return (a >= 0) ? a / b : -((-a + b - 1) / b); }

// Chebyshev distance transform over the 16³ page grid (two-pass chamfer with the full
// 26-neighbourhood), seeded with 0 at resident pages.
void chebyshevDistance(std::vector<int>& dist) {
  auto at = [&](int x, int y, int z) -> int& { return dist[x + kPages * (y + kPages * z)]; };
  for (int pass = 0; pass < 2; ++pass) {
    const int step = pass == 0 ? 1 : -1;
    const int begin = pass == 0 ? 0 : kPages - 1;
    for (int z = begin; z >= 0 && z < kPages; z += step)
      for (int y = begin; y >= 0 && y < kPages; y += step)
        for (int x = begin; x >= 0 && x < kPages; x += step) {
          int best = at(x, y, z);
          // Neighbours already visited in this pass's order.
          for (int dz = -1; dz <= 0; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
                int nx = x + dx * step, ny = y + dy * step, nz = z + dz * step;
                if (nx < 0 || ny < 0 || nz < 0 || nx >= kPages || ny >= kPages || nz >= kPages)
                  continue;
                best = std::min(best, at(nx, ny, nz) + 1);
              }
          at(x, y, z) = best;
        }
  }
}
}  // namespace

glm::uvec4 CascadeImage::toroidalOffset() const {
  auto wrap = [](int v) { return std::uint32_t(((v % kPages) + kPages) % kPages); };
  return {wrap(originBrick.x), wrap(originBrick.y), wrap(originBrick.z), 0u};
}

glm::vec3 CascadeImage::toCascade(const glm::dvec3& world) const {
  glm::dvec3 index = (world - worldOrigin) / voxelSize;
  return glm::vec3(index - glm::dvec3(originBrick) * double(layout::kBrickCells));
}

glm::dvec3 CascadeImage::toWorld(const glm::vec3& cascade) const {
  return worldOrigin +
         (glm::dvec3(cascade) + glm::dvec3(originBrick) * double(layout::kBrickCells)) * voxelSize;
}

std::uint32_t CascadeImage::pageIndex(glm::ivec3 p) const {
  glm::uvec4 o = toroidalOffset();
  std::uint32_t x = (std::uint32_t(p.x) + o.x) & 15u;
  std::uint32_t y = (std::uint32_t(p.y) + o.y) & 15u;
  std::uint32_t z = (std::uint32_t(p.z) + o.z) & 15u;
  return x + 16u * (y + 16u * z);
}

std::size_t CascadeImage::gpuBytes() const {
  return 4 * (pageTable.size() + distanceAtlas.size() + albedoAtlas.size() + emissionAtlas.size());
}

glm::ivec3 cascadeOriginAround(const World& world, const glm::dvec3& center) {
  glm::dvec3 index = (center - world.origin) / world.voxelSize;
  glm::ivec3 brick(int(std::floor(index.x / 8.0)), int(std::floor(index.y / 8.0)),
                   int(std::floor(index.z / 8.0)));
  return brick - glm::ivec3(kPages / 2);
}

glm::ivec3 cascadeOriginForWorld(const World& world) {
  glm::ivec3 lo = world.indexMin(), hi = world.indexMax();
  glm::ivec3 loBrick(floorDiv(lo.x, 8), floorDiv(lo.y, 8), floorDiv(lo.z, 8));
  glm::ivec3 hiBrick(floorDiv(hi.x - 1, 8), floorDiv(hi.y - 1, 8), floorDiv(hi.z - 1, 8));
  glm::ivec3 span = hiBrick - loBrick + 1;
  // Centre the world's bricks in the window; a world wider than 16 bricks is cropped evenly.
  return loBrick + (span - kPages) / 2;
}

CascadeImage buildCascade(const World& world, glm::ivec3 originBrick) {
  CascadeImage c;
  c.voxelSize = world.voxelSize;
  c.worldOrigin = world.origin;
  c.originBrick = originBrick;
  c.pageTable.assign(layout::kCascadePageCount, 0u);

  std::vector<int> dist(layout::kCascadePageCount, 1 << 20);
  std::vector<const Brick*> local(layout::kCascadePageCount, nullptr);
  for (const Brick& b : world.bricks) {
    glm::ivec3 p = b.coord - originBrick;
    if (p.x < 0 || p.y < 0 || p.z < 0 || p.x >= kPages || p.y >= kPages || p.z >= kPages)
      continue;
    int i = p.x + kPages * (p.y + kPages * p.z);
    local[i] = &b;
    dist[i] = 0;
  }
  chebyshevDistance(dist);

  // Slots are assigned in (z,y,x) page order so the atlas is deterministic.
  for (int z = 0; z < kPages; ++z)
    for (int y = 0; y < kPages; ++y)
      for (int x = 0; x < kPages; ++x) {
        int i = x + kPages * (y + kPages * z);
        std::uint32_t entry;
        if (const Brick* b = local[i]) {
          std::uint32_t slot = c.residentBricks++;
          entry = layout::kPageResidentBit | slot;
          std::size_t d0 = c.distanceAtlas.size();
          c.distanceAtlas.resize(d0 + layout::kBrickDistanceWords, 0u);
          for (std::uint32_t s = 0; s < layout::kBrickSampleCount; ++s)
            c.distanceAtlas[d0 + s / 2] |= std::uint32_t(b->distance[s]) << (16 * (s & 1));
          c.albedoAtlas.insert(c.albedoAtlas.end(), b->albedo.begin(), b->albedo.end());
          c.emissionAtlas.insert(c.emissionAtlas.end(), b->emission.begin(), b->emission.end());
        } else {
          int k = dist[i];
          entry = k >= (1 << 20) ? kFarBound : std::uint32_t(std::max(0, k - 1) * 8);
        }
        c.pageTable[c.pageIndex({x, y, z})] = entry;
      }
  // Vulkan buffers cannot be empty: keep one zero slot for an empty window.
  if (c.residentBricks == 0) {
    c.distanceAtlas.assign(layout::kBrickDistanceWords, 0u);
    c.albedoAtlas.assign(layout::kBrickMaterialCount, 0u);
    c.emissionAtlas.assign(layout::kBrickMaterialCount, 0u);
  }
  return c;
}

}  // namespace sdfstream
