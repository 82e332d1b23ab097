#include "viewer/view_picture.h"

#include <algorithm>

#include "demo/bitmap_font.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream::viewer {
namespace {

// One colour per cascade (0 = finest), distinct at a glance.
constexpr glm::u8vec3 kCascadeColours[8] = {{230, 60, 60},  {240, 160, 40}, {230, 220, 60},
                                            {80, 200, 80},  {60, 200, 220}, {70, 110, 240},
                                            {170, 90, 230}, {230, 230, 230}};

}  // namespace

std::string_view viewModeName(ViewMode mode) {
  switch (mode) {
    case ViewMode::Final:
      return "final";
    case ViewMode::Direct:
      return "direct";
    case ViewMode::Indirect:
      return "indirect";
    case ViewMode::Albedo:
      return "albedo";
    case ViewMode::Normals:
      return "normals";
    case ViewMode::Cascade:
      return "cascade";
    case ViewMode::Residency:
      return "residency";
    case ViewMode::ProbeStates:
      return "probe states";
    case ViewMode::ObjectRegions:
      return "object regions";
    case ViewMode::Count:
      break;
  }
  return "?";
}

ViewMode nextViewMode(ViewMode mode) { return ViewMode((int(mode) + 1) % int(ViewMode::Count)); }

Image8 viewPicture(ViewMode mode, const ShadedView& view, const HdrFrame& frame, bool indirectOn,
                   float exposureStops) {
  const int w = frame.width, h = frame.height;
  switch (mode) {
    case ViewMode::Final:
      return toneMap(indirectOn ? frame.final() : frame.direct, w, h, exposureStops);
    case ViewMode::Direct:
      return toneMap(frame.direct, w, h, exposureStops);
    case ViewMode::Indirect:
      return toneMap(frame.indirect, w, h, exposureStops + kIndirectStops);
    default:
      break;
  }
  Image8 image{w, h, std::vector<std::uint8_t>(std::size_t(w) * std::size_t(h) * 3, 0)};
  const std::size_t pixels = std::min(view.shaded.size(), std::size_t(w) * std::size_t(h));
  for (std::size_t p = 0; p < pixels; ++p) {
    const gpu_shared::ShadedHit& hit = view.shaded[p];
    if (mode == ViewMode::Residency && !(hit.flags & gpu_shared::kHitFlagHit) &&
        (hit.flags & gpu_shared::kHitFlagMissingData)) {
      image.rgb[3 * p + 0] = 230;
      image.rgb[3 * p + 1] = 60;
      image.rgb[3 * p + 2] = 60;
    }
    if (!(hit.flags & gpu_shared::kHitFlagHit) || mode == ViewMode::ProbeStates ||
        mode == ViewMode::ObjectRegions)
      continue;
    glm::u8vec3 c(0);
    if (mode == ViewMode::Albedo) {
      c = {hit.albedo & 255u, (hit.albedo >> 8) & 255u, (hit.albedo >> 16) & 255u};
    } else if (mode == ViewMode::Normals) {
      const glm::vec3 n = glm::clamp(glm::vec3(hit.normalT) * 0.5f + 0.5f, 0.0f, 1.0f);
      c = glm::u8vec3(n * 255.0f + 0.5f);
    } else if (mode == ViewMode::Residency) {
      c = hit.flags & gpu_shared::kHitFlagFellBack ? glm::u8vec3(240, 140, 30)
                                                   : glm::u8vec3(80, 200, 80);
    } else {
      c = kCascadeColours[(hit.flags >> gpu_shared::kHitCascadeShift) & 7u];
    }
    image.rgb[3 * p + 0] = c.r;
    image.rgb[3 * p + 1] = c.g;
    image.rgb[3 * p + 2] = c.b;
  }
  return image;
}

Image8 scaleNearest(const Image8& image, int width, int height) {
  if (image.width == width && image.height == height) return image;
  Image8 out{width, height,
             std::vector<std::uint8_t>(std::size_t(width) * std::size_t(height) * 3)};
  for (int y = 0; y < height; ++y) {
    const int sy = std::min(image.height - 1, int(std::int64_t(y) * image.height / height));
    for (int x = 0; x < width; ++x) {
      const int sx = std::min(image.width - 1, int(std::int64_t(x) * image.width / width));
      const std::uint8_t* in = &image.rgb[3 * (std::size_t(sy) * image.width + sx)];
      std::copy(in, in + 3, &out.rgb[3 * (std::size_t(y) * width + x)]);
    }
  }
  return out;
}

void drawHud(Image8& image, const std::vector<std::string>& lines, int scale) {
  int width = 0;
  for (const std::string& line : lines) width = std::max(width, font::textWidth(line, scale));
  const int pad = 3 * scale;
  const int bandW = std::min(image.width, width + 2 * pad);
  const int bandH = std::min(image.height, int(lines.size()) * font::kLineHeight * scale + 2 * pad);
  for (int y = 0; y < bandH; ++y)
    for (int x = 0; x < bandW; ++x)
      for (int c = 0; c < 3; ++c) {
        std::uint8_t& v = image.rgb[3 * (std::size_t(y) * image.width + x) + c];
        v = std::uint8_t(v / 3);
      }
  for (std::size_t i = 0; i < lines.size(); ++i)
    font::drawText(image, pad, pad + int(i) * font::kLineHeight * scale, lines[i],
                   glm::u8vec3(235, 235, 235), scale);
}

}  // namespace sdfstream::viewer
