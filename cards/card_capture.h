// Capturing a mesh's cards: what each card texel sees first, as a visibility sample (triangle and
// barycentric coordinates), then resolved into CardTexelGpu (albedo, emission, normal, depth)
// from the mesh's own materials. The GPU rasterizes the visibility (cards/card_rasterizer.h);
// captureCardsCpu is its CPU reference, the same orthographic rasterization at texel centres;
// both resolve through resolveCardTexels, so materials agree exactly where the visibility does.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "cards/card_layout.h"
#include "world/triangle_scene.h"

namespace sdfstream {

struct CardVisibility {
  std::uint32_t triangle = 0;  // triangle index + 1; 0: the texel sees nothing
  glm::vec2 bary{0.0f};        // barycentric coordinates of the triangle's vertices 1 and 2
};

// One card texel of each card, in MeshCards texel order (texelCount entries): the nearest
// triangle whose projection contains the texel centre (edges included; equal depths go to the
// lower triangle index, as the GPU's LESS depth test in draw order). O(texels × triangles):
// a reference for tests, not for production meshes.
std::vector<CardVisibility> captureCardsCpu(const TriangleScene& mesh, const MeshCards& cards);

// The texel a visibility sample of card `card` describes: position from the barycentric
// coordinates (its depth), the triangle's geometric normal turned to face the card, albedo and
// emission from the mesh's materials (sampleAlbedo / sampleEmission, as the path tracer and
// the object SDFs). triangle == 0 gives the empty texel (all zero, depth -1).
gpu_shared::CardTexelGpu resolveCardTexel(const TriangleScene& mesh,
                                          const gpu_shared::CardGpu& card,
                                          const CardVisibility& sample);

// resolveCardTexel over every texel (visibility.size() must equal cards.texelCount, else
// std::invalid_argument).
std::vector<gpu_shared::CardTexelGpu> resolveCardTexels(const TriangleScene& mesh,
                                                        const MeshCards& cards,
                                                        std::span<const CardVisibility> visibility);

}  // namespace sdfstream
