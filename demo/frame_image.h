// Turns a frame's primary-ray hits into a picture: a simple direct-light preview (sun + sky
// ambient + emission, tone-mapped) until the GI core supplies indirect light, and PNG output.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/sdf_layout.h"

namespace sdfstream {

struct Image8 {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row-major from the top-left pixel
};

struct PreviewLighting {
  glm::vec3 sunDirection = glm::normalize(glm::vec3(0.4f, 0.8f, 0.3f));  // towards the sun
  glm::vec3 sunColor{2.2f, 2.1f, 1.9f};
  glm::vec3 skyColor{0.45f, 0.55f, 0.7f};
  float exposure = 1.0f;
};

// Shades hits (as written by the trace pass) into an sRGB image. Misses show the sky gradient.
Image8 shadeHits(std::span<const gpu_shared::TraceHit> hits, int width, int height,
                 const PreviewLighting& lighting = {});

// Writes a PNG atomically (temp file + rename). Throws InputError(Io) on failure.
void writePng(const std::filesystem::path& path, const Image8& image);

}  // namespace sdfstream
