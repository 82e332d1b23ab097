// Error metrics of the GI against the reference: relMSE of irradiance at
// points, and FLIP between tone-mapped images (reference/flip.h, included here so that one
// header gives every metric). The tone map below is the one FLIP inputs go through.
#pragma once

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "reference/flip.h"

namespace sdfstream::reference {

// Relative mean squared error (Rousselle et al. 2011's relMSE, per point and channel):
//   e_i = 1/3 Σ_c (test_ic − ref_ic)² / (ref_ic² + epsilon)
//   relMSE = mean of e_i over the points left after discarding the floor(N·discardTopFraction)
//            largest e_i.
// The defaults discard the top 0.1% (and say so in the reports): a handful of
// fireflies in the test or the reference must not decide the score; with fewer than 1,000 points
// nothing is discarded. epsilon (in squared irradiance units) keeps near-black points from
// dominating. Non-finite errors count as +∞ (discarded first, otherwise the result is +∞).
// Returns 0 for empty input. Throws std::invalid_argument when the spans differ in length or
// discardTopFraction is outside [0, 1).
double relMSE(std::span<const glm::vec3> test, std::span<const glm::vec3> reference,
              double discardTopFraction = 0.001, double epsilon = 1e-2);

// ACES filmic curve, Narkowicz's 2015 fit ("ACES Filmic Tone Mapping Curve"), per channel:
//   f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), clamped to [0, 1], x = radiance × exposure
// (negative and NaN x give 0, +∞ gives 1).
// Output is linear display-referred RGB in [0, 1]: what FLIP takes. Encoding it to sRGB (below)
// for a PNG and decoding it again, as FLIP's own tool does with PNG inputs, returns the same
// values, so images compared here and PNGs written for people agree.
glm::vec3 toneMapAces(const glm::vec3& radiance, float exposure = 1.0f);
// Tone-maps a whole image (same order as the input).
std::vector<glm::vec3> toneMapAces(std::span<const glm::vec3> radiance, float exposure = 1.0f);

// sRGB transfer functions (IEC 61966-2-1) per channel, for values in [0, 1].
glm::vec3 linearToSrgb(const glm::vec3& linear);
glm::vec3 srgbToLinear(const glm::vec3& encoded);

}  // namespace sdfstream::reference
