// LDR-FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild 2020, "FLIP: A
// Difference Evaluator for Alternating Images", Proc. ACM CGIT 3(2)), implemented from the
// paper's description (the mean FLIP between tone-mapped images). Per pixel, an
// error in [0, 1] that approximates what an observer flipping between the two images notices.
//
// Pipeline (paper section numbers):
//  colour (§4.1): linear RGB → YyCxCz (linearised CIELAB, so filtering is linear) → per channel
//    spatial filter approximating the contrast sensitivity functions (spatial-domain sums of
//    Gaussians, parameters of the paper's Table 1) → linear RGB clamped to [0, 1] → L*a*b* →
//    Hunt adjustment (a*, b* scaled by 0.01·L*) → HyAB distance |ΔL*| + ‖Δ(a*, b*)‖ → raised to
//    qc = 0.7 and compressed to [0, 1] relative to the largest distance in the gamut (the
//    Hunt-adjusted green–blue distance): errors below pc = 0.4 of it map linearly to [0, pt =
//    0.95], the rest to [0.95, 1].
//  features (§4.2): on the achromatic channel (luminance Y/Yn of the unfiltered image), edges by
//    first and points by second derivatives of a Gaussian with σ = 0.5 · 0.082° (in pixels:
//    × pixels per degree); ΔEf = (max(|‖edge_ref‖ − ‖edge_test‖|, |‖point_ref‖ − ‖point_test‖|)
//    / √2)^qf with qf = 0.5.
//  combination (§4.3): ΔE = ΔEc^(1 − ΔEf): feature differences amplify colour differences.
// Image borders are extended by clamping to the edge pixel.
#pragma once

#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace sdfstream::reference {

// Pixels per degree of visual angle for a monitor `widthMetres` wide with `pixelsX` columns seen
// from `distanceMetres`.
double pixelsPerDegree(double distanceMetres, double widthMetres, double pixelsX);
// FLIP's default observer: 0.7 m from a 0.7 m wide monitor of 3840 columns (≈ 67.02 ppd).
inline const double kFlipDefaultPpd = pixelsPerDegree(0.7, 0.7, 3840.0);

struct FlipResult {
  std::vector<float> error;  // per pixel, in [0, 1], rows top to bottom
  double mean = 0.0;         // mean of `error`
};

// FLIP between two images of the same size, both linear RGB in [0, 1] (tone-mapped, e.g. with
// toneMapAces, or sRGB images decoded to linear); values outside [0, 1] are clamped. The measure
// is symmetric in its colour term and in its feature term. Throws std::invalid_argument when the
// sizes do not match width × height or the size or ppd is not positive.
FlipResult flip(std::span<const glm::vec3> reference, std::span<const glm::vec3> test, int width,
                int height, double pixelsPerDegree = kFlipDefaultPpd);

}  // namespace sdfstream::reference
