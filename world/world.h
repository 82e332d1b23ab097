// The in-memory world: a sparse set of 8³ SDF bricks with materials, in one world index space.
// This is what import produces, what world_io writes and reads, and what the cascade builder
// consumes. CPU only: nothing here knows about Vulkan (ARCHITECTURE.md, dependency rule).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/sdf_layout.h"

namespace sdfstream {

namespace layout = gpu_shared;

// One brick: distances at 9³ samples (8³ cells + apron, see sdf_layout.h) and per-cell materials.
struct Brick {
  glm::ivec3 coord{0};  // brick coordinate: covers index cells [8*coord, 8*coord + 8)
  // fp16 distances in voxel units, clamped to +-kNarrowBand, sample (x,y,z) at x + 9*(y + 9*z).
  std::array<std::uint16_t, layout::kBrickSampleCount> distance{};
  // Per cell (x + 8*(y + 8*z)), material of the nearest surface: RGBA8 sRGB base colour...
  std::array<std::uint32_t, layout::kBrickMaterialCount> albedo{};
  // ...and RGB9E5 linear emission (values above 1 kept).
  std::array<std::uint32_t, layout::kBrickMaterialCount> emission{};
};

struct World {
  double voxelSize = 0.0;             // metres per voxel
  glm::dvec3 origin{0.0};             // world position of index (0,0,0)
  std::vector<Brick> bricks;          // sorted by (z, y, x) of coord; unique coords
  std::string source;                 // file name the world was imported from (no directory)

  // Bounds of the brick cells in index space (inclusive min, exclusive max); empty world: 0,0.
  glm::ivec3 indexMin() const;
  glm::ivec3 indexMax() const;
  glm::dvec3 worldMin() const { return origin + glm::dvec3(indexMin()) * voxelSize; }
  glm::dvec3 worldMax() const { return origin + glm::dvec3(indexMax()) * voxelSize; }
};

// Brick helpers shared by import, IO and cascade code.
inline int brickSampleIndex(int x, int y, int z) {
  return x + int(layout::kBrickSamples) * (y + int(layout::kBrickSamples) * z);
}
inline int brickCellIndex(int x, int y, int z) {
  return x + int(layout::kBrickCells) * (y + int(layout::kBrickCells) * z);
}
// Orders bricks (z, y, x) so worlds are written deterministically.
bool brickCoordLess(const glm::ivec3& a, const glm::ivec3& b);

}  // namespace sdfstream
