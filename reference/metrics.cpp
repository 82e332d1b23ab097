#include "reference/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sdfstream::reference {

double relMSE(std::span<const glm::vec3> test, std::span<const glm::vec3> reference,
              double discardTopFraction, double epsilon) {
  if (test.size() != reference.size())
    throw std::invalid_argument("relMSE: test and reference differ in length");
  if (!(discardTopFraction >= 0.0 && discardTopFraction < 1.0))
    throw std::invalid_argument("relMSE: discardTopFraction must be in [0, 1)");
  if (test.empty()) return 0.0;
  std::vector<double> errors(test.size());
  for (std::size_t i = 0; i < test.size(); ++i) {
    double e = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double t = test[i][c], r = reference[i][c];
      e += (t - r) * (t - r) / (r * r + epsilon);
    }
    e /= 3.0;
    errors[i] = std::isfinite(e) ? e : std::numeric_limits<double>::infinity();
  }
  const auto discard = std::size_t(std::floor(double(errors.size()) * discardTopFraction));
  const std::size_t keep = errors.size() - discard;
  // The `keep` smallest errors, summed in ascending order (deterministic, least rounding).
  std::sort(errors.begin(), errors.end());
  double sum = 0.0;
  for (std::size_t i = 0; i < keep; ++i) sum += errors[i];
  return sum / double(keep);
}

glm::vec3 toneMapAces(const glm::vec3& radiance, float exposure) {
  glm::vec3 out;
  for (int c = 0; c < 3; ++c) {
    const float x = radiance[c] * exposure;
    if (!(x > 0.0f)) {  // negative, zero or NaN
      out[c] = 0.0f;
    } else if (x > 1e4f) {  // the curve is 1 (clamped) long before; avoids ∞/∞ for huge x
      out[c] = 1.0f;
    } else {
      out[c] = std::min(1.0f, (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f));
    }
  }
  return out;
}

std::vector<glm::vec3> toneMapAces(std::span<const glm::vec3> radiance, float exposure) {
  std::vector<glm::vec3> out(radiance.size());
  for (std::size_t i = 0; i < radiance.size(); ++i) out[i] = toneMapAces(radiance[i], exposure);
  return out;
}

glm::vec3 linearToSrgb(const glm::vec3& linear) {
  glm::vec3 out;
  for (int c = 0; c < 3; ++c) {
    const float v = std::clamp(linear[c], 0.0f, 1.0f);
    out[c] = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
  }
  return out;
}

glm::vec3 srgbToLinear(const glm::vec3& encoded) {
  glm::vec3 out;
  for (int c = 0; c < 3; ++c) {
    const float v = std::clamp(encoded[c], 0.0f, 1.0f);
    out[c] = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
  }
  return out;
}

}  // namespace sdfstream::reference
