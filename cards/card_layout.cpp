#include "cards/card_layout.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sdfstream {

using gpu_shared::CardGpu;

MeshCards layoutCards(glm::vec3 boxMin, glm::vec3 boxMax, float voxel,
                      const CardSettings& settings) {
  if (!(std::isfinite(voxel) && voxel > 0.0f))
    throw std::invalid_argument("layoutCards: voxel must be finite and > 0");
  if (settings.minTexels < 1 || settings.minTexels > settings.maxTexels ||
      settings.maxTexels > 4096 || !(settings.texelsPerVoxel > 0.0f) ||
      !(settings.depthPad >= 0.0f))
    throw std::invalid_argument("layoutCards: invalid CardSettings");
  MeshCards out;
  // A flat mesh still gets a box one voxel deep, centred on it.
  for (int a = 0; a < 3; ++a) {
    const float extent = boxMax[a] - boxMin[a];
    if (extent < voxel) {
      const float grow = 0.5f * (voxel - extent);
      boxMin[a] -= grow;
      boxMax[a] += grow;
    }
  }
  out.boxMin = boxMin;
  out.boxMax = boxMax;
  const glm::vec3 extent = boxMax - boxMin;
  const float pad = settings.depthPad * std::max(extent.x, std::max(extent.y, extent.z));
  const float texel = voxel / settings.texelsPerVoxel;
  auto texels = [&](float length) {
    const float wanted = std::ceil(length / texel - 1e-4f);
    return std::clamp(static_cast<std::uint32_t>(std::max(wanted, 1.0f)), settings.minTexels,
                      settings.maxTexels);
  };
  std::uint32_t first = 0;
  for (std::uint32_t k = 0; k < gpu_shared::kCardsPerMesh; ++k) {
    const std::uint32_t axis = k / 2, side = k % 2;
    const std::uint32_t u = (axis + 1) % 3, v = (axis + 2) % 3;
    const std::uint32_t width = texels(extent[u]), height = texels(extent[v]);
    CardGpu& c = out.cards[k];
    const float plane = side == 0 ? boxMax[axis] + pad : boxMin[axis] - pad;
    c.plane = glm::vec4(boxMin[u], boxMin[v], plane, extent[axis] + 2.0f * pad);
    c.texel = glm::vec4(extent[u] / float(width), extent[v] / float(height), 0.0f, 0.0f);
    c.info = glm::uvec4(axis, side, width, height);
    c.first = glm::uvec4(first, 0, out.lightTexels[1], out.lightTexels[2]);
    first += width * height;
    for (std::uint32_t l = 1; l < gpu_shared::kCardLightLevels; ++l) {
      const glm::uvec2 size = gpu_shared::cardLightSize(c, l);
      out.lightTexels[l] += size.x * size.y;
    }
  }
  out.texelCount = first;
  out.lightTexels[0] = first;
  return out;
}

glm::ivec3 cardAxes(const CardGpu& card) {
  const int axis = int(card.info.x);
  return {(axis + 1) % 3, (axis + 2) % 3, axis};
}

glm::vec3 cardViewDirection(const CardGpu& card) {
  glm::vec3 d(0.0f);
  d[card.info.x] = card.info.y == 0 ? -1.0f : 1.0f;
  return d;
}

glm::vec3 cardTexelCentre(const CardGpu& card, std::uint32_t i, std::uint32_t j) {
  const glm::ivec3 a = cardAxes(card);
  glm::vec3 p;
  p[a.x] = card.plane.x + (float(i) + 0.5f) * card.texel.x;
  p[a.y] = card.plane.y + (float(j) + 0.5f) * card.texel.y;
  p[a.z] = card.plane.z;
  return p;
}

float cardDepthOf(const CardGpu& card, glm::vec3 p) {
  const float along = p[card.info.x];
  return card.info.y == 0 ? card.plane.z - along : along - card.plane.z;
}

gpu_shared::CardCapturePush cardClipFromObject(const CardGpu& card) {
  const glm::ivec3 a = cardAxes(card);
  const float extentU = card.texel.x * float(card.info.z);
  const float extentV = card.texel.y * float(card.info.w);
  gpu_shared::CardCapturePush push{};
  push.clipFromObject[0][a.x] = 2.0f / extentU;
  push.clipFromObject[0].w = -2.0f * card.plane.x / extentU - 1.0f;
  push.clipFromObject[1][a.y] = 2.0f / extentV;
  push.clipFromObject[1].w = -2.0f * card.plane.y / extentV - 1.0f;
  // z = depth / extent, depth = ±(plane − p[axis]) as cardDepthOf.
  const float s = card.info.y == 0 ? -1.0f : 1.0f;
  push.clipFromObject[2][a.z] = s / card.plane.w;
  push.clipFromObject[2].w = -s * card.plane.z / card.plane.w;
  return push;
}

}  // namespace sdfstream
