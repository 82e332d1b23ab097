#include "demo/frame_image.h"

#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "shaders/shared/color_codec.h"

namespace sdfstream {
namespace {
float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
std::uint8_t linearToSrgb8(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  float s = c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return std::uint8_t(std::lround(s * 255.0f));
}
}  // namespace

Image8 shadeHits(std::span<const gpu_shared::TraceHit> hits, int width, int height,
                 const PreviewLighting& light) {
  Image8 img{width, height, std::vector<std::uint8_t>(std::size_t(width) * height * 3)};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const auto& h = hits[std::size_t(y) * width + x];
      glm::vec3 c;
      if (h.flags & gpu_shared::kHitFlagHit) {
        glm::vec4 a = gpu_shared::unpackAlbedo(h.albedo);
        glm::vec3 albedo(srgbToLinear(a.r), srgbToLinear(a.g), srgbToLinear(a.b));
        glm::vec3 n(h.normalT);
        float sun = std::max(0.0f, glm::dot(n, light.sunDirection));
        float skyVisibility = 0.6f + 0.4f * n.y;  // crude hemisphere ambient
        c = albedo * (light.sunColor * sun + light.skyColor * skyVisibility) +
            gpu_shared::unpackRgb9e5(h.emission);
      } else {
        float v = float(y) / float(std::max(1, height - 1));
        c = glm::mix(light.skyColor * 1.6f, glm::vec3(0.85f, 0.85f, 0.8f), v);
      }
      c *= light.exposure;
      c = c / (glm::vec3(1.0f) + c);  // Reinhard: keeps HDR emission from clipping harshly
      std::uint8_t* px = &img.rgb[(std::size_t(y) * width + x) * 3];
      px[0] = linearToSrgb8(c.r);
      px[1] = linearToSrgb8(c.g);
      px[2] = linearToSrgb8(c.b);
    }
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
