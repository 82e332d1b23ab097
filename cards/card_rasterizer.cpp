#include "cards/card_rasterizer.h"

#include <array>
#include <cstring>

#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/context.h"
#include "shaders/embedded_shaders.h"

namespace sdfstream {

using gpu_shared::CardGpu;

CardRasterizer::CardRasterizer(gpu::Context& ctx)
    : ctx_(&ctx),
      raster_(ctx,
              VisibilityStages{gpu::ShaderId::card_visibility_vs, gpu::ShaderId::card_visibility_fs,
                               sizeof(gpu_shared::CardCapturePush), false, "card capture"}) {}

std::vector<CardVisibility> CardRasterizer::capture(const TriangleScene& mesh,
                                                    const MeshCards& cards) {
  // Cards side by side in one target: card k's texel (i, j) is pixel (x_k + i, j).
  std::array<std::uint32_t, gpu_shared::kCardsPerMesh> x{};
  std::array<gpu_shared::CardCapturePush, gpu_shared::kCardsPerMesh> push{};
  std::array<VisibilityView, gpu_shared::kCardsPerMesh> views{};
  std::uint32_t width = 0, height = 0;
  for (std::uint32_t k = 0; k < gpu_shared::kCardsPerMesh; ++k) {
    const CardGpu& card = cards.cards[k];
    x[k] = width;
    push[k] = cardClipFromObject(card);
    views[k] = {x[k], 0, card.info.z, card.info.w, &push[k]};
    width += card.info.z;
    height = std::max(height, card.info.w);
  }

  std::vector<glm::vec4> positions(mesh.positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) positions[i] = glm::vec4(mesh.positions[i], 1);
  const std::size_t indexCount = mesh.triangles.size() * 3;
  gpu::Buffer positionBuffer(*ctx_, positions.size() * sizeof(glm::vec4), gpu::BufferKind::Upload);
  gpu::Buffer indexBuffer(*ctx_, indexCount * sizeof(std::uint32_t), gpu::BufferKind::Upload);
  if (!positions.empty())
    std::memcpy(positionBuffer.mapped(), positions.data(), positions.size() * sizeof(glm::vec4));
  if (indexCount)
    std::memcpy(indexBuffer.mapped(), mesh.triangles.data(), indexCount * sizeof(std::uint32_t));
  const std::size_t pixels = std::size_t(width) * height;
  gpu::Buffer readback(*ctx_, VisibilityRaster::outputBytes(width, height),
                       gpu::BufferKind::Readback);

  gpu::CommandBatch batch = ctx_->beginBatch(1);
  batch.record("card capture", [&](VkCommandBuffer cb) {
    raster_.record(cb, positionBuffer, indexBuffer, std::uint32_t(mesh.triangles.size()), width,
                   height, views, readback);
  });
  batch.submitAndWait();
  lastMilliseconds_ = batch.timings().front().milliseconds;

  const auto* ids = static_cast<const std::uint32_t*>(readback.mapped());
  const auto* bary = reinterpret_cast<const glm::vec2*>(ids + pixels);
  std::vector<CardVisibility> out(cards.texelCount);
  for (std::uint32_t k = 0; k < gpu_shared::kCardsPerMesh; ++k) {
    const CardGpu& card = cards.cards[k];
    for (std::uint32_t j = 0; j < card.info.w; ++j)
      for (std::uint32_t i = 0; i < card.info.z; ++i) {
        const std::size_t pixel = std::size_t(x[k] + i) + std::size_t(width) * j;
        CardVisibility& v = out[card.first.x + i + card.info.z * j];
        v.triangle = ids[pixel];
        v.bary = v.triangle ? bary[pixel] : glm::vec2(0.0f);
      }
  }
  return out;
}

}  // namespace sdfstream
