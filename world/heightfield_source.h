// Heightfield terrain as an SdfSource: a grayscale PNG heightmap, bilinear between pixels, whose
// signed distance is computed analytically per sample (no level set, no per-LOD data), so a
// kilometre terrain costs only its decoded pixels in memory.
//
// Geometry: pixel (i, j) (column i, row j from the top of the image) is the surface point
//   (origin.x + i·metresPerPixel, origin.y + value/fullScale·heightScale, origin.z +
//   j·metresPerPixel)
// with fullScale = 255 for 8-bit and 65535 for 16-bit images. Between pixels the height is
// bilinear; outside the image the edge pixels extend (clamped), but boundsMin/Max cover only the
// image, so a tile builder never visits the extension. Points with y > h(x, z) are outside.
//
// Distance (signedDistance): the sign is exact for the bilinear surface (sign of y − h(x, z)).
// The magnitude is a two-step tangent-plane estimate: d0 = (y − h)/sqrt(1 + |∇h|²) with ∇h
// interpolated bilinearly from central differences at the pixels, then the distance to the
// tangent plane at the foot point p − d0·n. It is exact for planes; on a curved surface the error
// is second order in d/R (R the curvature radius), and it never exceeds the vertical distance
// |y − h| (an upper bound of the true distance). tests/terrain checks |Δ| ≤ 0.5 voxel against
// the brute-force distance to the heightfield's triangulation inside the band.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "world/sdf_source.h"

namespace sdfstream {

struct HeightfieldDesc {
  std::filesystem::path png;    // 8- or 16-bit PNG (RGB is converted to luminance)
  double metresPerPixel = 5.0;  // > 0
  double heightScale = 100.0;   // metres at full scale (255 or 65535); >= 0
  glm::dvec3 origin{0.0};       // world position of pixel (0,0) at height value 0
  // Linear base colour of flat lowland (grass); slopes turn to rock, high flat ground to snow.
  glm::vec3 albedo{0.18f, 0.30f, 0.08f};
};

// Decoded heights in metres, with their placement. Immutable after construction: every const
// member is safe to call from any number of threads.
class Heightfield {
 public:
  // heights: width·height values, row-major (x fastest), metres above origin.y. width, height ≥ 2.
  Heightfield(int width, int height, std::vector<float> heights, double metresPerPixel,
              glm::dvec3 origin);

  // The most pixels a heightmap may have (16384²). Loading costs about 15 bytes a pixel at peak
  // (stb's 8- and 16-bit buffers, heights, gradients), so this is ~4 GiB: a real terrain fits,
  // and the size is refused from the header before anything is decoded.
  static constexpr double kMaxPixels = double(1 << 28);
  // The most bytes stb's first decode buffer may take (pixels × the file's channels × bytes per
  // channel): 16-bit RGBA at kMaxPixels would be 2 GiB in one allocation.
  static constexpr double kMaxDecodedBytes = double(1u << 30);

  // Reads desc.png with stb_image. Throws InputError naming the file: Io (cannot open),
  // Malformed (no PNG signature, or not decodable; stb's reason given), Empty (fewer than 2×2
  // pixels), TooLarge (more than kMaxPixels or kMaxDecodedBytes), Malformed for metresPerPixel ≤ 0
  // / heightScale < 0, Truncated (a PNG chunk longer than the bytes left: stb would allocate what
  // the length claims before noticing).
  // Safe on untrusted input: PNG only, because stb's other decoders (BMP, TGA, PSD, ...) accept a
  // file that ends right after a header declaring 16384² pixels and return zeros for the rest,
  // and a PNG's pixels must all be present (so their count is bounded by the file's size).
  static Heightfield load(const HeightfieldDesc& desc);

  int width() const { return width_; }
  int height() const { return height_; }
  double metresPerPixel() const { return mpp_; }
  glm::dvec3 origin() const { return origin_; }
  float pixel(int i, int j) const { return heights_[std::size_t(j) * width_ + i]; }

  // World y of the surface at world (x, z): bilinear, clamped to the image edge.
  double heightAt(double x, double z) const;
  // (∂h/∂x, ∂h/∂z) at world (x, z): central differences at pixels, bilinear between them.
  glm::dvec2 gradientAt(double x, double z) const;
  // Signed distance in metres (see the header comment for its accuracy).
  double signedDistance(const glm::dvec3& p) const;
  // Conservative world-y range of the surface over the world rectangle [x0,x1]×[z0,z1].
  glm::dvec2 heightRange(double x0, double z0, double x1, double z1) const;

  glm::dvec3 boundsMin() const;
  glm::dvec3 boundsMax() const;

 private:
  glm::dvec2 toPixel(double x, double z) const;
  int width_, height_;
  double mpp_;
  glm::dvec3 origin_;
  std::vector<float> heights_;        // metres above origin.y
  std::vector<glm::vec2> gradients_;  // per pixel, central differences
  // Min/max of heights_ per block of kBlock×kBlock cells (pixels [kBlock·b, kBlock·b + kBlock]
  // inclusive, so bilinear values inside a block lie within its range).
  static constexpr int kBlock = 16;
  int blocksX_, blocksZ_;
  std::vector<glm::vec2> blockRange_;
  float minHeight_, maxHeight_;
};

// Terrain colour at a surface point: desc albedo on flat lowland, rock on slopes, snow on high
// flat ground, with a little deterministic per-pixel variation. Linear RGB.
glm::vec3 terrainAlbedo(const Heightfield& field, glm::vec3 lowland, double x, double z);

// The SdfSource for a heightfield. sampleBrick writes distances in LOD voxel units clamped to
// ±kNarrowBand (min-union with `out`) and the terrain colour in cells where the terrain is nearer
// than out.materialDistance (nearest-corner rule of sdf_source.h); every LOD is sampled from the
// same analytic surface, so the LOD contract there holds trivially. Bricks entirely more than the
// band below the surface get −kNarrowBand and return false (no surface), bricks entirely above it
// are left untouched and return false. prepareLod records the spec; releaseLod does nothing.
// Thread-safe.
std::unique_ptr<SdfSource> makeHeightfieldSource(const HeightfieldDesc& desc);
std::unique_ptr<SdfSource> makeHeightfieldSource(Heightfield field, glm::vec3 albedo);

}  // namespace sdfstream
