#include "demo/frame_image.h"

#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "shaders/shared/frame_layout.h"

namespace sdfstream {
namespace {
// The GPU picture's encoder (frame_compose.comp), so both round alike.
std::uint8_t linearToSrgb8(float c) { return std::uint8_t(gpu_shared::frameSrgb8(c)); }
}  // namespace

glm::vec3 acesFitted(glm::vec3 c) { return gpu_shared::frameAcesFitted(c); }

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
    out->insert(out->end(), static_cast<std::uint8_t*>(data),
                static_cast<std::uint8_t*>(data) + size);
  };
  if (!stbi_write_png_to_func(sink, &bytes, image.width, image.height, 3, image.rgb.data(),
                              image.width * 3))
    throw InputError(InputErrorKind::Io, path.string(), "PNG encoding failed");
  writeFileAtomically(path, bytes.data(), bytes.size());
}

Image8 addedLight(const Image8& with, const Image8& without, float gain) {
  if (with.width != without.width || with.height != without.height ||
      with.rgb.size() != without.rgb.size())
    throw std::invalid_argument("addedLight: the two images differ in size");
  Image8 out{with.width, with.height, std::vector<std::uint8_t>(with.rgb.size())};
  for (std::size_t i = 0; i < with.rgb.size(); ++i) {
    const float added = (float(with.rgb[i]) - float(without.rgb[i])) * gain;
    out.rgb[i] = std::uint8_t(std::lround(std::clamp(added, 0.0f, 255.0f)));
  }
  return out;
}

}  // namespace sdfstream
