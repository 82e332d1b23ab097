// Where a mesh's six cards lie (shaders/shared/card_layout.h has the conventions): the object
// box's faces, each an orthographic view into the box at a texel size tied to the object's SDF
// voxel, so a card resolves about what the object's SDF resolves (GS slides b, "Storing
// lighting information"; Flax's surface atlas sizes tiles by texels per metre the same way).
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

#include "shaders/shared/card_layout.h"

namespace sdfstream {

struct CardSettings {
  float texelsPerVoxel = 1.0f;  // card texels per object-SDF voxel along each card axis
  // Texels per card axis are clamped into [minTexels, maxTexels] (the texel stretches to fit).
  std::uint32_t minTexels = 4, maxTexels = 128;
  // The card planes sit this fraction of the box's longest extent outside the box, so surfaces
  // on a face are not clipped by the view's depth range.
  float depthPad = 0.01f;
};

struct MeshCards {
  std::array<gpu_shared::CardGpu, gpu_shared::kCardsPerMesh> cards{};
  std::uint32_t texelCount = 0;  // sum of width × height over the six cards
  // Light texels of an instance at each light level (level 0: texelCount).
  std::array<std::uint32_t, gpu_shared::kCardLightLevels> lightTexels{};
  glm::vec3 boxMin{0}, boxMax{0};
};

// Cards of the object-space box [boxMin, boxMax] at `voxel` object units per SDF voxel. Card k
// has axis k / 2 and side k % 2; texels are numbered card by card. Degenerate boxes (a flat
// mesh) get at least one voxel of extent on every axis. voxel must be finite and > 0 and the
// settings valid (1 <= minTexels <= maxTexels <= 4096, texelsPerVoxel > 0, depthPad >= 0),
// else std::invalid_argument.
MeshCards layoutCards(glm::vec3 boxMin, glm::vec3 boxMax, float voxel,
                      const CardSettings& settings = {});

// The card's axes: u, v (along its texel rows and columns) and the view direction (into the box).
glm::ivec3 cardAxes(const gpu_shared::CardGpu& card);  // (u axis, v axis, view axis) indices
glm::vec3 cardViewDirection(const gpu_shared::CardGpu& card);
// Object-space centre of texel (i, j) on the card's plane.
glm::vec3 cardTexelCentre(const gpu_shared::CardGpu& card, std::uint32_t i, std::uint32_t j);
// Object units from the card's plane to object point p along the view direction.
float cardDepthOf(const gpu_shared::CardGpu& card, glm::vec3 p);
// The capture's orthographic map: clip x, y in [-1, 1] over the card, z in [0, 1] over its depth
// extent; three rows applied to (p, 1).
gpu_shared::CardCapturePush cardClipFromObject(const gpu_shared::CardGpu& card);

}  // namespace sdfstream
