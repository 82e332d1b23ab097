// C++ face of the probe (DDGI) math in shaders/probe_math.glsl -- the very same functions the
// GPU passes run (the .cpp includes the GLSL file) -- plus ProbeTexels, the CPU reference of one
// probe's texture update (blend + border copy). Formulas and their sources are documented at
// each function in probe_math.glsl; units are cascade voxels, directions are unit vectors.
// All functions are pure and thread-safe. Nothing here reads untrusted input.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/probe_layout.h"

namespace sdfstream::probe {

// ---- Ray directions
// Fibonacci point i of n on the unit sphere (i < n), z-up.
glm::vec3 sphericalFibonacci(std::uint32_t i, std::uint32_t n);
// rotation * sphericalFibonacci(i, n): ray i of a probe this frame.
glm::vec3 rayDirection(std::uint32_t i, std::uint32_t n, const glm::mat3& rotation);
// A rotation drawn uniformly from SO(3) (Shoemake's random unit quaternion), the same for the
// same seed on every platform (std::mt19937_64, own uniform conversion).
glm::mat3 randomRotation(std::uint64_t seed);

// ---- Octahedral mapping
glm::vec2 octEncode(glm::vec3 unitDir);  // -> [-1,1]²
glm::vec3 octDecode(glm::vec2 oct);      // [-1,1]² -> unit direction
// Interior texel (0..interior-1 per axis) -> its centre in [-1,1]² / its direction.
glm::vec2 texelCentreOct(glm::uvec2 texel, std::uint32_t interior);
glm::vec3 texelDirection(glm::uvec2 texel, std::uint32_t interior);
// Direction -> position in the bordered tile, in texels (interior spans [1, interior + 1)).
glm::vec2 tileCoord(glm::vec3 unitDir, std::uint32_t interior);
// Tile texel -> the tile texel it copies (itself when interior). tile = interior + 2.
glm::uvec2 borderSource(glm::uvec2 tileTexel, std::uint32_t tile);
// Candidate k < 8 of the border texels that copy tile texel t (those whose borderSource is t).
glm::uvec2 borderCopyCandidate(glm::uvec2 tileTexel, std::uint32_t tile, std::uint32_t k);

// ---- Blending
float irradianceWeight(glm::vec3 texelDir, glm::vec3 rayDir);              // max(0, cos)
float depthWeight(glm::vec3 texelDir, glm::vec3 rayDir, float sharpness);  // max(0, cos)^s
glm::vec3 irradianceFromSums(glm::vec4 weightedRadianceAndWeight);         // pi * rgb / a
glm::vec3 encodeIrradiance(glm::vec3 irradiance, float gamma);             // E^(1/gamma)
glm::vec3 decodeIrradiance(glm::vec3 stored, float gamma);                 // s^gamma
glm::vec3 hysteresisBlend(glm::vec3 oldValue, glm::vec3 fresh, float hysteresis);
float adjustHysteresis(glm::vec3 oldStored, glm::vec3 freshStored, float hysteresis);
float rayDepth(float hitT, bool hit, bool backface, float maxDistance, float backfaceScale);

// ---- Sampling weights
float chebyshevWeight(glm::vec2 moments, float distance, float minVariance);
float backfaceWeight(glm::vec3 dirToProbe, glm::vec3 normal);
float trilinearWeight(glm::vec3 alpha, std::uint32_t corner);
glm::vec3 selfShadowBias(glm::vec3 normal, glm::vec3 view, float minAxialSpacing, float biasScale);
float crushWeight(float w, float threshold);

// One probe's textures on the CPU: the irradiance tile (8x8, encoded RGB) and the depth tile
// (16x16, mean and mean of squares), both row-major with borders, as the GPU atlas stores a
// probe's tile. Starts at zero (a newly awake probe). ~3.9 KB.
class ProbeTexels {
 public:
  static constexpr std::uint32_t kIrradianceTile = gpu_shared::kProbeIrradianceTexels;
  static constexpr std::uint32_t kDepthTile = gpu_shared::kProbeDepthTexels;

  struct Settings {
    float irradianceGamma = gpu_shared::kProbeIrradianceGamma;
    float depthSharpness = gpu_shared::kProbeDepthSharpness;
    bool adaptiveHysteresis = false;  // per-texel change heuristic (M21 Sec. 4.3), irradiance only
  };

  ProbeTexels() = default;
  explicit ProbeTexels(const Settings& settings) : settings_(settings) {}

  // Blends one frame of rays into every interior texel, then fills the borders.
  // directions: unit ray directions; radiance: linear RGB each ray brought back; depth: the
  // distance each ray records (see rayDepth). All three the same length (asserted).
  // A texel that no ray weights (possible with very few rays) keeps its value.
  void update(std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance,
              std::span<const float> depth, float irradianceHysteresis, float depthHysteresis);

  // Copies every border texel from its source (borderSource). update() calls it.
  void fillBorders();

  // Stored tiles, index y * tile + x.
  std::span<glm::vec3> irradianceTile() { return irradiance_; }
  std::span<const glm::vec3> irradianceTile() const { return irradiance_; }
  std::span<glm::vec2> depthTile() { return depth_; }
  std::span<const glm::vec2> depthTile() const { return depth_; }

  // Decoded irradiance of interior texel (x, y) in 0..5.
  glm::vec3 irradianceTexel(glm::uvec2 texel) const;
  // Bilinear lookups in direction d, as a GPU sampler reads the tile (encoded values filtered,
  // then decoded). Reads border texels: call after fillBorders()/update().
  glm::vec3 sampleIrradiance(glm::vec3 unitDir) const;
  glm::vec2 sampleDepth(glm::vec3 unitDir) const;

  const Settings& settings() const { return settings_; }

 private:
  Settings settings_;
  std::vector<glm::vec3> irradiance_ =
      std::vector<glm::vec3>(kIrradianceTile * kIrradianceTile, glm::vec3(0.0f));
  std::vector<glm::vec2> depth_ = std::vector<glm::vec2>(kDepthTile * kDepthTile, glm::vec2(0.0f));
};

}  // namespace sdfstream::probe
