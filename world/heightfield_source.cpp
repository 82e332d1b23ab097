#include "world/heightfield_source.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>

#include <stb_image.h>

#include "core/error.h"
#include "core/printable.h"
#include "world/color_pack.h"
#include "world/png_chunks.h"

namespace sdfstream {
namespace {

using Kind = InputErrorKind;

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// Integer hash → [0, 1): per-pixel colour variation that does not depend on the sampling order.
float hash01(std::int64_t i, std::int64_t j) {
  std::uint64_t h =
      std::uint64_t(i) * 0x9E3779B97F4A7C15ull ^ std::uint64_t(j) * 0xC2B2AE3D27D4EB4Full;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return float(h >> 40) / float(1 << 24);
}

// stb's reason for the last failure, printable: for an unknown PNG chunk stb puts the chunk's
// four type bytes from the file into it ("\n]gX PNG chunk not known").
std::string stbReason() { return printable(stbi_failure_reason()); }

class HeightfieldSource final : public SdfSource {
 public:
  HeightfieldSource(Heightfield field, glm::vec3 albedo)
      : field_(std::move(field)), albedo_(albedo) {}

  glm::dvec3 boundsMin() const override { return field_.boundsMin(); }
  glm::dvec3 boundsMax() const override { return field_.boundsMax(); }
  // Each LOD's slot is written once before that LOD is sampled, so concurrent sampling of
  // another LOD never races with it.
  void prepareLod(const PartitionSpec& spec, int lod) override {
    specs_.at(std::size_t(lod)) = spec;
  }
  void releaseLod(int) override {}
  double estimateBytes(const PartitionSpec&) const override {
    return double(field_.width()) * field_.height() * 16.0;  // heights + gradients (+ blocks)
  }
  std::vector<std::string> materialNames() const override { return {"terrain"}; }

  bool sampleBrick(int lod, glm::ivec3 brick, BrickSamples& out) const override {
    const PartitionSpec& spec = specs_.at(std::size_t(lod));
    const double vox = spec.lodVoxelSize(lod);
    const double band = double(layout::kNarrowBand) * vox;
    const glm::dvec3 lo = spec.origin + vox * glm::dvec3(brick * int(layout::kBrickCells));
    const glm::dvec3 hi = lo + vox * double(layout::kBrickCells);
    // A surface point within `band` of the brick lies above the grown footprint, so the range of
    // heights there decides the two cheap cases.
    const glm::dvec2 range = field_.heightRange(lo.x - band, lo.z - band, hi.x + band, hi.z + band);
    if (lo.y - range.y > band) return false;  // wholly above: nothing to add to a min-union
    const bool inside = range.x - hi.y > band;

    bool surface = false;
    constexpr int S = int(layout::kBrickSamples), C = int(layout::kBrickCells);
    std::array<float, layout::kBrickSampleCount> mine;
    for (int z = 0; z < S; ++z)
      for (int y = 0; y < S; ++y)
        for (int x = 0; x < S; ++x) {
          float d = -layout::kNarrowBand;
          if (!inside) {
            const glm::dvec3 p = lo + vox * glm::dvec3(x, y, z);
            d = float(std::clamp(field_.signedDistance(p) / vox, -double(layout::kNarrowBand),
                                 double(layout::kNarrowBand)));
            surface |= std::abs(d) < layout::kNarrowBand;
          }
          const auto i = std::size_t(brickSampleIndex(x, y, z));
          mine[i] = d;
          out.distance[i] = std::min(out.distance[i], d);
        }
    // Materials per sdf_source.h: this source's |d| at the cell's nearest corner decides.
    for (int z = 0; z < C; ++z)
      for (int y = 0; y < C; ++y)
        for (int x = 0; x < C; ++x) {
          float d = layout::kNarrowBand;
          for (int corner = 0; corner < 8; ++corner)
            d = std::min(d, std::abs(mine[std::size_t(brickSampleIndex(
                                x + (corner & 1), y + (corner >> 1 & 1), z + (corner >> 2)))]));
          const auto c = std::size_t(brickCellIndex(x, y, z));
          if (d < out.materialDistance[c]) {
            out.materialDistance[c] = d;
            const glm::dvec3 p = lo + vox * (glm::dvec3(x, y, z) + 0.5);
            out.albedo[c] = packAlbedo(glm::vec4(terrainAlbedo(field_, albedo_, p.x, p.z), 1.0f));
            out.emission[c] = 0;
            out.emitter[c] = 0;
          }
        }
    return surface;
  }

 private:
  Heightfield field_;
  glm::vec3 albedo_;
  std::array<PartitionSpec, PartitionSpec::kMaxLods> specs_{};
};

}  // namespace

Heightfield::Heightfield(int width, int height, std::vector<float> heights, double metresPerPixel,
                         glm::dvec3 origin)
    : width_(width),
      height_(height),
      mpp_(metresPerPixel),
      origin_(origin),
      heights_(std::move(heights)) {
  if (width_ < 2 || height_ < 2 || heights_.size() != std::size_t(width_) * height_ ||
      !(mpp_ > 0.0))
    throw std::invalid_argument("Heightfield: need width, height >= 2, matching heights, mpp > 0");
  gradients_.resize(heights_.size());
  for (int j = 0; j < height_; ++j)
    for (int i = 0; i < width_; ++i) {
      const int i0 = std::max(i - 1, 0), i1 = std::min(i + 1, width_ - 1);
      const int j0 = std::max(j - 1, 0), j1 = std::min(j + 1, height_ - 1);
      gradients_[std::size_t(j) * width_ + i] =
          glm::vec2((pixel(i1, j) - pixel(i0, j)) / float((i1 - i0) * mpp_),
                    (pixel(i, j1) - pixel(i, j0)) / float((j1 - j0) * mpp_));
    }
  blocksX_ = (width_ - 2) / kBlock + 1;
  blocksZ_ = (height_ - 2) / kBlock + 1;
  blockRange_.assign(
      std::size_t(blocksX_) * blocksZ_,
      glm::vec2(std::numeric_limits<float>::max(), -std::numeric_limits<float>::max()));
  for (int j = 0; j < height_; ++j)
    for (int i = 0; i < width_; ++i) {
      // A pixel on a block edge belongs to both blocks' cells.
      const float h = pixel(i, j);
      for (int bj = std::max(0, (j - 1) / kBlock); bj <= std::min(blocksZ_ - 1, j / kBlock); ++bj)
        for (int bi = std::max(0, (i - 1) / kBlock); bi <= std::min(blocksX_ - 1, i / kBlock);
             ++bi) {
          glm::vec2& r = blockRange_[std::size_t(bj) * blocksX_ + bi];
          r = glm::vec2(std::min(r.x, h), std::max(r.y, h));
        }
    }
  const auto [mn, mx] = std::minmax_element(heights_.begin(), heights_.end());
  minHeight_ = *mn;
  maxHeight_ = *mx;
}

Heightfield Heightfield::load(const HeightfieldDesc& desc) {
  const std::string file = desc.png.string();
  if (!(desc.metresPerPixel > 0.0) || !std::isfinite(desc.metresPerPixel))
    throw InputError(Kind::Malformed, file, "metresPerPixel must be a finite number > 0");
  if (!(desc.heightScale >= 0.0) || !std::isfinite(desc.heightScale))
    throw InputError(Kind::Malformed, file, "heightScale must be a finite number >= 0");
  std::ifstream probe(desc.png, std::ios::binary);
  std::error_code ec;
  if (!probe || std::filesystem::is_directory(desc.png, ec))
    throw InputError(Kind::Io, file, std::string("cannot open: ") + std::strerror(errno));
  // PNG only (see heightfield_source.h): the signature decides before stb sees the file.
  if (!hasPngSignature(probe))
    throw InputError(Kind::Malformed, file, "not a PNG file (a heightmap must be a PNG)");
  checkPngChunks(probe, std::filesystem::file_size(desc.png, ec), file);
  probe.close();
  int w = 0, h = 0, channels = 0;
  if (stbi_info(file.c_str(), &w, &h, &channels) == 0)
    throw InputError(Kind::Malformed, file, "not a decodable image: " + stbReason());
  if (w < 2 || h < 2)
    throw InputError(Kind::Empty, file,
                     "a heightmap needs at least 2x2 pixels, this one has " + std::to_string(w) +
                         "x" + std::to_string(h));
  if (double(w) * double(h) > kMaxPixels)
    throw InputError(Kind::TooLarge, file,
                     std::to_string(w) + "x" + std::to_string(h) + " pixels, more than the " +
                         std::to_string(std::int64_t(kMaxPixels)) + " a heightmap may have");
  const double decoded =
      double(w) * double(h) * double(channels) * (stbi_is_16_bit(file.c_str()) ? 2.0 : 1.0);
  if (decoded > kMaxDecodedBytes)
    throw InputError(Kind::TooLarge, file,
                     std::to_string(w) + "x" + std::to_string(h) + " pixels of " +
                         std::to_string(channels) + " channels decode to more than " +
                         std::to_string(std::int64_t(kMaxDecodedBytes) >> 20) + " MiB");
  // stbi_load_16 widens 8-bit images to 16 bits (v·257), so full scale is always 65535.
  stbi_us* data = stbi_load_16(file.c_str(), &w, &h, &channels, 1);
  if (!data)
    throw InputError(Kind::Malformed, file, "cannot decode image: " + stbReason());
  std::vector<float> heights(std::size_t(w) * h);
  for (std::size_t i = 0; i < heights.size(); ++i)
    heights[i] = float(double(data[i]) / 65535.0 * desc.heightScale);
  stbi_image_free(data);
  return Heightfield(w, h, std::move(heights), desc.metresPerPixel, desc.origin);
}

glm::dvec2 Heightfield::toPixel(double x, double z) const {
  return glm::dvec2(std::clamp((x - origin_.x) / mpp_, 0.0, double(width_ - 1)),
                    std::clamp((z - origin_.z) / mpp_, 0.0, double(height_ - 1)));
}

double Heightfield::heightAt(double x, double z) const {
  const glm::dvec2 u = toPixel(x, z);
  const int i = std::min(int(u.x), width_ - 2), j = std::min(int(u.y), height_ - 2);
  const double fx = u.x - i, fz = u.y - j;
  const double h0 = pixel(i, j) + (pixel(i + 1, j) - pixel(i, j)) * fx;
  const double h1 = pixel(i, j + 1) + (pixel(i + 1, j + 1) - pixel(i, j + 1)) * fx;
  return origin_.y + h0 + (h1 - h0) * fz;
}

glm::dvec2 Heightfield::gradientAt(double x, double z) const {
  const glm::dvec2 u = toPixel(x, z);
  const int i = std::min(int(u.x), width_ - 2), j = std::min(int(u.y), height_ - 2);
  const double fx = u.x - i, fz = u.y - j;
  auto g = [&](int a, int b) { return glm::dvec2(gradients_[std::size_t(b) * width_ + a]); };
  const glm::dvec2 g0 = g(i, j) + (g(i + 1, j) - g(i, j)) * fx;
  const glm::dvec2 g1 = g(i, j + 1) + (g(i + 1, j + 1) - g(i, j + 1)) * fx;
  return g0 + (g1 - g0) * fz;
}

double Heightfield::signedDistance(const glm::dvec3& p) const {
  const double vertical = p.y - heightAt(p.x, p.z);
  if (vertical == 0.0) return 0.0;
  auto normal = [&](double x, double z) {
    const glm::dvec2 g = gradientAt(x, z);
    return glm::normalize(glm::dvec3(-g.x, 1.0, -g.y));
  };
  // Step 1: distance to the tangent plane under p; step 2: to the tangent plane at its foot.
  const glm::dvec3 n0 = normal(p.x, p.z);
  const glm::dvec3 foot = p - vertical * n0.y * n0;
  const glm::dvec3 onSurface(foot.x, heightAt(foot.x, foot.z), foot.z);
  const double d1 = glm::dot(p - onSurface, normal(foot.x, foot.z));
  double magnitude = std::abs(d1);
  // A foot on the other side means the plane model broke down (a fold); fall back to step 1.
  if ((d1 > 0.0) != (vertical > 0.0)) magnitude = std::abs(vertical * n0.y);
  magnitude = std::min(magnitude, std::abs(vertical));
  return std::copysign(magnitude, vertical);
}

glm::dvec2 Heightfield::heightRange(double x0, double z0, double x1, double z1) const {
  const glm::dvec2 a = toPixel(x0, z0), b = toPixel(x1, z1);
  const int i0 = int(std::floor(a.x)), j0 = int(std::floor(a.y));
  const int i1 = int(std::ceil(b.x)), j1 = int(std::ceil(b.y));
  float lo = std::numeric_limits<float>::max(), hi = -lo;
  if (i1 - i0 <= 2 * kBlock && j1 - j0 <= 2 * kBlock) {
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        lo = std::min(lo, pixel(i, j));
        hi = std::max(hi, pixel(i, j));
      }
  } else {
    const int bi1 = std::min(blocksX_ - 1, std::max(i0, i1 - 1) / kBlock);
    const int bj1 = std::min(blocksZ_ - 1, std::max(j0, j1 - 1) / kBlock);
    for (int bj = std::min(j0 / kBlock, bj1); bj <= bj1; ++bj)
      for (int bi = std::min(i0 / kBlock, bi1); bi <= bi1; ++bi) {
        const glm::vec2 r = blockRange_[std::size_t(bj) * blocksX_ + bi];
        lo = std::min(lo, r.x);
        hi = std::max(hi, r.y);
      }
  }
  return glm::dvec2(origin_.y + lo, origin_.y + hi);
}

glm::dvec3 Heightfield::boundsMin() const { return origin_ + glm::dvec3(0.0, minHeight_, 0.0); }

glm::dvec3 Heightfield::boundsMax() const {
  return origin_ + glm::dvec3((width_ - 1) * mpp_, maxHeight_, (height_ - 1) * mpp_);
}

glm::vec3 terrainAlbedo(const Heightfield& field, glm::vec3 lowland, double x, double z) {
  const glm::dvec2 g = field.gradientAt(x, z);
  const double up = 1.0 / std::sqrt(1.0 + glm::dot(g, g));  // cos(slope)
  const double lo = field.boundsMin().y, hi = field.boundsMax().y;
  const double t = hi > lo ? (field.heightAt(x, z) - lo) / (hi - lo) : 0.0;
  const glm::dvec3 rock(0.30, 0.27, 0.24), snow(0.85, 0.87, 0.90);
  glm::dvec3 c = glm::mix(glm::dvec3(lowland), rock, smoothstep(0.92, 0.75, up));  // > ~23°: rock
  c = glm::mix(c, snow, smoothstep(0.75, 0.9, t) * smoothstep(0.8, 0.92, up));
  const auto px = std::int64_t(std::floor((x - field.origin().x) / field.metresPerPixel()));
  const auto pz = std::int64_t(std::floor((z - field.origin().z) / field.metresPerPixel()));
  return glm::vec3(c * (0.9 + 0.2 * double(hash01(px, pz))));
}

std::unique_ptr<SdfSource> makeHeightfieldSource(const HeightfieldDesc& desc) {
  return makeHeightfieldSource(Heightfield::load(desc), desc.albedo);
}

std::unique_ptr<SdfSource> makeHeightfieldSource(Heightfield field, glm::vec3 albedo) {
  return std::make_unique<HeightfieldSource>(std::move(field), albedo);
}

}  // namespace sdfstream
