// One camera-centred cascade of the streamed SDF: a 16³ toroidal page table over a brick atlas
// (ARCHITECTURE.md "Cascade"; Godot SDFGI slides, 128³ cascades). This is the CPU image of what
// the GPU holds: gpu_cascade uploads it as is, and the CPU reference tracer reads it directly.
//
// For now (vertical slice) a cascade is built whole from an in-memory World at the world's own
// voxel size (cascade 0); scrolling and streaming replace the whole-build later without
// changing this layout.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "world/world.h"

namespace sdfstream {

struct CascadeImage {
  double voxelSize = 0.0;        // metres per cell
  glm::dvec3 worldOrigin{0.0};   // world position of index (0,0,0) (the world's origin)
  glm::ivec3 originBrick{0};     // world brick coordinate of the cascade's page (0,0,0)
  std::vector<std::uint32_t> pageTable;  // kCascadePageCount entries, toroidally addressed
  std::vector<std::uint32_t> distanceAtlas;  // slots * kBrickDistanceWords
  std::vector<std::uint32_t> albedoAtlas;    // slots * kBrickMaterialCount
  std::vector<std::uint32_t> emissionAtlas;  // slots * kBrickMaterialCount
  std::uint32_t residentBricks = 0;

  // (originBrick mod 16) as the shader's push constant wants it.
  glm::uvec4 toroidalOffset() const;
  // Cascade-relative voxel coordinates of a world position (double in, float out: the GPU only
  // ever sees these small numbers).
  glm::vec3 toCascade(const glm::dvec3& world) const;
  glm::dvec3 toWorld(const glm::vec3& cascade) const;
  // Index into pageTable for the page at cascade-local page coordinate (0..15 each).
  std::uint32_t pageIndex(glm::ivec3 localPage) const;
  std::size_t gpuBytes() const;
};

// The cascade origin brick that centres a 16³-page window on a world position.
glm::ivec3 cascadeOriginAround(const World& world, const glm::dvec3& center);

// The origin brick that best covers the whole world (centred on its bounds).
glm::ivec3 cascadeOriginForWorld(const World& world);

// Builds the page table and atlas for the window starting at originBrick. Empty pages get the
// conservative bound (k-1)*8 voxels, k = Chebyshev page distance to the nearest resident page
// inside the window (a straight ray leaving the window never comes back, so bricks outside it
// cannot be hit before the ray exits).
CascadeImage buildCascade(const World& world, glm::ivec3 originBrick);

}  // namespace sdfstream
