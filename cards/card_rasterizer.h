// The GPU side of card capture: the visibility raster (raster/visibility_raster.h: triangle + 1
// and barycentrics per pixel, a D32 depth test) draws a mesh's six orthographic card views
// (cards/card_layout.h) side by side into one target, in one submission, and reads it back as
// CardVisibility in the cards' texel order. Capture runs once per mesh (its attributes are
// object-space), so a blocking readback is fine; captureCardsCpu (card_capture.h) is the reference
// it is tested against.
//
// Needs a queue family with graphics (Context::queueFamily); lavapipe, NVIDIA, AMD and Intel
// expose one. Move-only. Thread safety: as for the Context.
#pragma once

#include <cstdint>
#include <vector>

#include "cards/card_capture.h"
#include "raster/visibility_raster.h"

namespace sdfstream::gpu {
class Context;
}

namespace sdfstream {

class CardRasterizer {
 public:
  // Throws std::runtime_error naming what is missing when the Context's queue has no graphics
  // or the device cannot render to the target formats (R32_UINT, R32G32_SFLOAT, D32_SFLOAT).
  explicit CardRasterizer(gpu::Context& ctx);

  // One sample per card texel (MeshCards texel order). Blocks until the GPU is done. The mesh
  // must have passed validateObjectMesh (indices in range).
  std::vector<CardVisibility> capture(const TriangleScene& mesh, const MeshCards& cards);
  // GPU time of the last capture's draw + readback copies (0 without timestamps).
  double lastMilliseconds() const { return lastMilliseconds_; }

 private:
  gpu::Context* ctx_;
  VisibilityRaster raster_;
  double lastMilliseconds_ = 0.0;
};

}  // namespace sdfstream
