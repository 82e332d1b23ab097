// Turns a frame's linear radiance into a picture -- exposure, a filmic tone map (ACES, Hill's
// fitted RRT+ODT) and sRGB encoding -- and writes PNGs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace sdfstream {

struct Image8 {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row-major from the top-left pixel
};

// ACES filmic curve on linear sRGB-primaries radiance (Stephen Hill's fit of the RRT+ODT, as in
// BakingLab): input matrix -> rational fit -> output matrix, clamped to [0, 1]. Black stays
// black; NaN and negative input become 0.
glm::vec3 acesFitted(glm::vec3 linear);

// Radiance (row-major, width × height) × 2^exposureStops -> ACES fitted -> sRGB 8 bits.
// Non-finite values become black (and are counted in *nonFinite when given).
Image8 toneMap(std::span<const glm::vec3> radiance, int width, int height, float exposureStops,
               std::size_t* nonFinite = nullptr);

// Rec. 709 luminance of linear RGB.
inline float luminance(glm::vec3 c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

// Writes a PNG atomically (temp file + rename). Throws InputError(Io) on failure.
void writePng(const std::filesystem::path& path, const Image8& image);

// What `with` adds to `without` (same size), per channel, times gain, clamped to [0, 255]: where
// an effect adds light and of which colour (the demo's card bounce). Throws std::invalid_argument
// when the sizes differ.
Image8 addedLight(const Image8& with, const Image8& without, float gain);

}  // namespace sdfstream
