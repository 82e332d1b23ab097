#include "cards/card_capture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <glm/gtc/type_precision.hpp>

#include "world/color_pack.h"

namespace sdfstream {

using gpu_shared::CardGpu;
using gpu_shared::CardTexelGpu;

namespace {

// Vertices snap to 1/256 texel, as rasterizers' sub-pixel grids (Vulkan requires >= 4 bits;
// lavapipe and NVIDIA use 8), so edge functions are exact integers and a texel centre on an edge
// shared by two triangles is covered by exactly one of them (a consistent tie rule), never by
// none: the reference is watertight like the hardware.
constexpr double kSubTexels = 256.0;
using Fixed = glm::i64vec2;

// Twice the signed area of (a, b, p), exact.
std::int64_t edge(Fixed a, Fixed b, Fixed p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

double edgeExact(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

// Tie rule for a texel centre exactly on edge a -> b of a positively oriented triangle: the edge
// owns it when it points one way; the neighbour across the edge walks it the other way and does
// not. This direction is the top-left rule in Vulkan's framebuffer (y down) and reproduces
// lavapipe's coverage texel for texel (tests/cards); any consistent rule would be watertight.
bool ownsTies(Fixed a, Fixed b) {
  const std::int64_t dy = b.y - a.y, dx = b.x - a.x;
  return dy < 0 || (dy == 0 && dx > 0);
}

void captureCard(const TriangleScene& mesh, const CardGpu& card, std::span<CardVisibility> out) {
  const glm::ivec3 a = cardAxes(card);
  const std::uint32_t width = card.info.z, height = card.info.w;
  std::vector<float> depth(out.size(), std::numeric_limits<float>::infinity());
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3 tri = mesh.triangles[t];
    Fixed q[3];
    glm::dvec2 r[3];
    float z[3];
    for (int c = 0; c < 3; ++c) {
      const glm::vec3 p = mesh.positions[tri[c]];
      // Texel coordinates: texel (i, j) has its centre at (i + 0.5, j + 0.5).
      const double x = (double(p[a.x]) - card.plane.x) / card.texel.x;
      const double y = (double(p[a.y]) - card.plane.y) / card.texel.y;
      q[c] = Fixed(std::llround(x * kSubTexels), std::llround(y * kSubTexels));
      r[c] = glm::dvec2(x, y);
      z[c] = cardDepthOf(card, p);
    }
    std::int64_t area = edge(q[0], q[1], q[2]);
    const double areaExact = edgeExact(r[0], r[1], r[2]);
    if (area == 0 || areaExact == 0.0) continue;  // edge-on: no coverage, as in the rasterizer
    // Orient positively; the barycentrics keep naming the original vertices 1 and 2.
    int v0 = 0, v1 = 1, v2 = 2;
    if (area < 0) {
      std::swap(v1, v2);
      area = -area;
    }
    const Fixed lo = glm::min(q[0], glm::min(q[1], q[2]));
    const Fixed hi = glm::max(q[0], glm::max(q[1], q[2]));
    const auto first = [](std::int64_t v) {  // first texel whose centre is >= v (sub-texels)
      return int(std::max<std::int64_t>(0, (v - 128 + 255) >> 8));
    };
    const int i0 = first(lo.x), j0 = first(lo.y);
    const int i1 = std::min<std::int64_t>(int(width) - 1, (hi.x - 128) >> 8);
    const int j1 = std::min<std::int64_t>(int(height) - 1, (hi.y - 128) >> 8);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const Fixed p(std::int64_t(i) * 256 + 128, std::int64_t(j) * 256 + 128);
        // w_k: weight of vertex k (the edge opposite it), all >= 0 inside.
        std::int64_t w[3];
        w[v0] = edge(q[v1], q[v2], p);
        w[v1] = edge(q[v2], q[v0], p);
        w[v2] = edge(q[v0], q[v1], p);
        if (w[0] < 0 || w[1] < 0 || w[2] < 0) continue;
        if ((w[v0] == 0 && !ownsTies(q[v1], q[v2])) || (w[v1] == 0 && !ownsTies(q[v2], q[v0])) ||
            (w[v2] == 0 && !ownsTies(q[v0], q[v1])))
          continue;
        // Barycentrics from the unsnapped positions, as rasterizers interpolate attributes.
        const glm::dvec2 c(double(i) + 0.5, double(j) + 0.5);
        const double b1d = edgeExact(r[2], r[0], c) / areaExact;
        const double b2d = edgeExact(r[0], r[1], c) / areaExact;
        const float b1 = float(b1d), b2 = float(b2d);
        const float d = (1.0f - b1 - b2) * z[0] + b1 * z[1] + b2 * z[2];
        if (d < 0.0f || d > card.plane.w) continue;  // outside the view's depth range
        const std::size_t texel = std::size_t(i) + std::size_t(width) * std::size_t(j);
        if (!(d < depth[texel])) continue;  // LESS: the first drawn keeps a tie
        depth[texel] = d;
        out[texel] = {t + 1, glm::vec2(b1, b2)};
      }
  }
}

}  // namespace

std::vector<CardVisibility> captureCardsCpu(const TriangleScene& mesh, const MeshCards& cards) {
  std::vector<CardVisibility> out(cards.texelCount);
  for (const CardGpu& card : cards.cards)
    captureCard(mesh, card,
                std::span<CardVisibility>(out).subspan(card.first.x, card.info.z * card.info.w));
  return out;
}

CardTexelGpu resolveCardTexel(const TriangleScene& mesh, const CardGpu& card,
                              const CardVisibility& sample) {
  CardTexelGpu texel{0u, 0u, 0u, -1.0f};
  if (sample.triangle == 0) return texel;
  const std::uint32_t t = sample.triangle - 1;
  const glm::uvec3 tri = mesh.triangles.at(t);
  const glm::vec3 v0 = mesh.positions[tri.x], v1 = mesh.positions[tri.y],
                  v2 = mesh.positions[tri.z];
  const glm::vec3 p = v0 + sample.bary.x * (v1 - v0) + sample.bary.y * (v2 - v0);
  const glm::vec3 view = cardViewDirection(card);
  glm::vec3 n = glm::cross(v1 - v0, v2 - v0);
  const float length = glm::length(n);
  n = length > 0.0f ? n / length : -view;
  if (glm::dot(n, view) > 0.0f) n = -n;  // the side the card sees
  texel.albedo = packAlbedo(sampleAlbedo(mesh, t, sample.bary));
  texel.emission = packRgb9e5(sampleEmission(mesh, t, sample.bary));
  texel.normal = gpu_shared::cardPackNormal(n);
  texel.depth = cardDepthOf(card, p);
  return texel;
}

std::vector<CardTexelGpu> resolveCardTexels(const TriangleScene& mesh, const MeshCards& cards,
                                            std::span<const CardVisibility> visibility) {
  if (visibility.size() != cards.texelCount)
    throw std::invalid_argument("resolveCardTexels: visibility size differs from texelCount");
  std::vector<CardTexelGpu> out(visibility.size());
  for (const CardGpu& card : cards.cards) {
    const std::size_t first = card.first.x, count = std::size_t(card.info.z) * card.info.w;
    for (std::size_t k = first; k < first + count; ++k)
      out[k] = resolveCardTexel(mesh, card, visibility[k]);
  }
  return out;
}

}  // namespace sdfstream
