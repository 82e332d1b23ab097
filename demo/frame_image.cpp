#include "demo/frame_image.h"

#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>

#include "core/atomic_dir.h"
#include "core/error.h"

namespace sdfstream {
namespace {
std::uint8_t linearToSrgb8(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  float s = c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return std::uint8_t(std::lround(s * 255.0f));
}
}  // namespace

glm::vec3 acesFitted(glm::vec3 c) {
  // sRGB -> (ACES2065-1 via the RRT's saturation) and back (Hill's ACESFitted.hlsl); rows.
  const glm::vec3 in0(0.59719f, 0.35458f, 0.04823f), in1(0.07600f, 0.90834f, 0.01566f),
      in2(0.02840f, 0.13383f, 0.83777f);
  const glm::vec3 out0(1.60475f, -0.53108f, -0.07367f), out1(-0.10208f, 1.10813f, -0.00605f),
      out2(-0.00327f, -0.07276f, 1.07602f);
  // `x > 0` is false for NaN: NaN and negative channels become 0.
  c = glm::vec3(c.r > 0.0f ? c.r : 0.0f, c.g > 0.0f ? c.g : 0.0f, c.b > 0.0f ? c.b : 0.0f);
  glm::vec3 v(glm::dot(in0, c), glm::dot(in1, c), glm::dot(in2, c));
  v = (v * (v + 0.0245786f) - 0.000090537f) / (v * (0.983729f * v + 0.4329510f) + 0.238081f);
  glm::vec3 o(glm::dot(out0, v), glm::dot(out1, v), glm::dot(out2, v));
  return glm::clamp(o, glm::vec3(0.0f), glm::vec3(1.0f));
}

Image8 toneMap(std::span<const glm::vec3> radiance, int width, int height, float exposureStops,
               std::size_t* nonFinite) {
  Image8 img{width, height, std::vector<std::uint8_t>(std::size_t(width) * height * 3)};
  const float scale = std::exp2(exposureStops);
  std::size_t bad = 0;
  for (std::size_t i = 0; i < std::size_t(width) * height; ++i) {
    glm::vec3 c = radiance[i];
    if (!std::isfinite(c.r) || !std::isfinite(c.g) || !std::isfinite(c.b)) {
      ++bad;
      c = glm::vec3(0.0f);
    }
    c = acesFitted(c * scale);
    img.rgb[i * 3 + 0] = linearToSrgb8(c.r);
    img.rgb[i * 3 + 1] = linearToSrgb8(c.g);
    img.rgb[i * 3 + 2] = linearToSrgb8(c.b);
  }
  if (nonFinite) *nonFinite = bad;
  return img;
}

void writePng(const std::filesystem::path& path, const Image8& image) {
  std::vector<std::uint8_t> bytes;
  auto sink = [](void* ctx, void* data, int size) {
    auto* out = static_cast<std::vector<std::uint8_t>*>(ctx);
    out->insert(out->end(), static_cast<std::uint8_t*>(data), static_cast<std::uint8_t*>(data) + size);
  };
  if (!stbi_write_png_to_func(sink, &bytes, image.width, image.height, 3, image.rgb.data(),
                              image.width * 3))
    throw InputError(InputErrorKind::Io, path.string(), "PNG encoding failed");
  writeFileAtomically(path, bytes.data(), bytes.size());
}

}  // namespace sdfstream
