#include "reference/flip.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sdfstream::reference {
namespace {

constexpr double kPi = 3.14159265358979323846;

// FLIP parameters (paper §4): colour exponent, error-redistribution knee and its target, feature
// exponent, and the edge detector's peak-to-trough width in degrees (2σ of its Gaussian).
constexpr double kQc = 0.7;
constexpr double kPc = 0.4;
constexpr double kPt = 0.95;
constexpr double kQf = 0.5;
constexpr double kFeatureWidthDegrees = 0.082;

// Spatial-domain contrast sensitivity of one opponent channel (§4.1): the sum of two Gaussians
//   S(x) = a1·√(π/b1)·exp(−π²x²/b1) + a2·√(π/b2)·exp(−π²x²/b2),  x in degrees.
struct Csf {
  double a1, b1, a2, b2;
};
constexpr Csf kCsfAchromatic{1.0, 0.0047, 0.0, 1e-5};
constexpr Csf kCsfRedGreen{1.0, 0.0053, 0.0, 1e-5};
constexpr Csf kCsfBlueYellow{34.1, 0.04, 13.5, 0.025};
constexpr double kCsfWidestB = 0.04;  // the largest b sets one kernel radius for all channels

using Plane = std::vector<float>;
using Kernel = std::vector<float>;  // odd length, centre in the middle

float clamp01(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }  // NaN → 0

// Correlation with a separable kernel (rows with `horizontal`, then columns with `vertical`),
// borders extended by the edge pixel.
Plane convolveSeparable(const Plane& in, int w, int h, const Kernel& horizontal,
                        const Kernel& vertical) {
  const int rh = int(horizontal.size() / 2), rv = int(vertical.size() / 2);
  Plane tmp(in.size()), out(in.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float sum = 0.0f;
      for (int i = -rh; i <= rh; ++i)
        sum += horizontal[i + rh] * in[std::size_t(y) * w + std::clamp(x + i, 0, w - 1)];
      tmp[std::size_t(y) * w + x] = sum;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float sum = 0.0f;
      for (int j = -rv; j <= rv; ++j)
        sum += vertical[j + rv] * tmp[std::size_t(std::clamp(y + j, 0, h - 1)) * w + x];
      out[std::size_t(y) * w + x] = sum;
    }
  return out;
}

// sRGB primaries, D65 (IEC 61966-2-1). The reference white is the image of RGB (1, 1, 1), so
// white and greys have exactly zero chroma.
const glm::dmat3 kRgbToXyz(glm::dvec3(0.4124564, 0.2126729, 0.0193339),
                           glm::dvec3(0.3575761, 0.7151522, 0.1191920),
                           glm::dvec3(0.1804375, 0.0721750, 0.9503041));
const glm::dmat3 kXyzToRgb = glm::inverse(kRgbToXyz);
const glm::dvec3 kWhite = kRgbToXyz * glm::dvec3(1.0);

// YyCxCz: CIELAB without its cube root, linear in XYZ so that filtering in it is meaningful.
glm::dvec3 rgbToYcxcz(const glm::dvec3& rgb) {
  const glm::dvec3 n = (kRgbToXyz * rgb) / kWhite;
  return {116.0 * n.y - 16.0, 500.0 * (n.x - n.y), 200.0 * (n.y - n.z)};
}

glm::dvec3 ycxczToRgb(const glm::dvec3& c) {
  const double y = (c.x + 16.0) / 116.0;
  const glm::dvec3 n(y + c.y / 500.0, y, y - c.z / 200.0);
  return kXyzToRgb * (n * kWhite);
}

// CIE L*a*b* (D65) with the Hunt adjustment of §4.1: chroma scaled by 0.01·L*, because
// chromatic differences look larger in brighter colours.
glm::dvec3 rgbToHuntLab(const glm::dvec3& rgb) {
  const glm::dvec3 n = (kRgbToXyz * rgb) / kWhite;
  auto f = [](double t) {
    constexpr double d = 6.0 / 29.0;
    return t > d * d * d ? std::cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
  };
  const double fx = f(n.x), fy = f(n.y), fz = f(n.z);
  const double l = 116.0 * fy - 16.0;
  return {l, 0.01 * l * 500.0 * (fx - fy), 0.01 * l * 200.0 * (fy - fz)};
}

double hyab(const glm::dvec3& p, const glm::dvec3& q) {
  return std::abs(p.x - q.x) + std::hypot(p.y - q.y, p.z - q.z);
}

// One Gaussian component exp(−π²(i/ppd)²/b) sampled at integer pixel offsets |i| ≤ radius.
Kernel csfComponent(double b, double ppd, int radius, double& sum) {
  Kernel k(std::size_t(2 * radius + 1));
  sum = 0.0;
  for (int i = -radius; i <= radius; ++i) {
    const double x = i / ppd;
    k[std::size_t(i + radius)] = float(std::exp(-kPi * kPi * x * x / b));
    sum += k[std::size_t(i + radius)];
  }
  return k;
}

// Filters one YyCxCz channel with its CSF. The 2D kernel a·√(π/b)·exp(−π²r²/b) factors into
// exp(−π²x²/b)·exp(−π²y²/b), so each Gaussian component is two 1D passes; the components are
// weighted so that the whole (square) 2D kernel sums to one, as the paper normalises it.
Plane csfFilter(const Plane& channel, int w, int h, const Csf& csf, double ppd, int radius) {
  double s1 = 0.0, s2 = 0.0;
  const Kernel k1 = csfComponent(csf.b1, ppd, radius, s1);
  const Kernel k2 = csfComponent(csf.b2, ppd, radius, s2);
  const double w1 = csf.a1 * std::sqrt(kPi / csf.b1) * s1 * s1;
  const double w2 = csf.a2 * std::sqrt(kPi / csf.b2) * s2 * s2;
  auto normalised = [](Kernel k, double sum) {
    for (float& v : k) v = float(v / sum);
    return k;
  };
  Plane out = convolveSeparable(channel, w, h, normalised(k1, s1), normalised(k1, s1));
  const float f1 = float(w1 / (w1 + w2));
  for (float& v : out) v *= f1;
  if (w2 > 0.0) {
    const Plane second = convolveSeparable(channel, w, h, normalised(k2, s2), normalised(k2, s2));
    const float f2 = float(w2 / (w1 + w2));
    for (std::size_t i = 0; i < out.size(); ++i) out[i] += f2 * second[i];
  }
  return out;
}

// Feature detectors of §4.2 along x: first (edge) or second (point) derivative of a Gaussian,
// positive weights scaled to sum to 1 and negative ones to −1. The 2D kernel is this 1D profile
// times a Gaussian across, normalised to sum to 1 (the 2D normalisation factors the same way).
struct FeatureKernels {
  Kernel edge, point, gaussian;
};

FeatureKernels featureKernels(double ppd) {
  const double sigma = 0.5 * kFeatureWidthDegrees * ppd;
  const int radius = int(std::ceil(3.0 * sigma));
  FeatureKernels k;
  std::vector<double> g, d1, d2;
  double gSum = 0.0, d1Pos = 0.0, d1Neg = 0.0, d2Pos = 0.0, d2Neg = 0.0;
  for (int i = -radius; i <= radius; ++i) {
    const double gi = std::exp(-double(i) * i / (2.0 * sigma * sigma));
    const double e = -i * gi;
    const double p = (double(i) * i / (sigma * sigma) - 1.0) * gi;
    g.push_back(gi);
    d1.push_back(e);
    d2.push_back(p);
    gSum += gi;
    (e > 0 ? d1Pos : d1Neg) += std::abs(e);
    (p > 0 ? d2Pos : d2Neg) += std::abs(p);
  }
  for (std::size_t i = 0; i < g.size(); ++i) {
    k.gaussian.push_back(float(g[i] / gSum));
    k.edge.push_back(float(d1[i] > 0 ? d1[i] / d1Pos : d1[i] / d1Neg));
    k.point.push_back(float(d2[i] > 0 ? d2[i] / d2Pos : d2[i] / d2Neg));
  }
  return k;
}

// Edge and point strengths (gradient norms of the x and y detector responses) of a luminance
// plane.
void detectFeatures(const Plane& luminance, int w, int h, const FeatureKernels& k, Plane& edges,
                    Plane& points) {
  const Plane ex = convolveSeparable(luminance, w, h, k.edge, k.gaussian);
  const Plane ey = convolveSeparable(luminance, w, h, k.gaussian, k.edge);
  const Plane px = convolveSeparable(luminance, w, h, k.point, k.gaussian);
  const Plane py = convolveSeparable(luminance, w, h, k.gaussian, k.point);
  edges.resize(luminance.size());
  points.resize(luminance.size());
  for (std::size_t i = 0; i < luminance.size(); ++i) {
    edges[i] = std::hypot(ex[i], ey[i]);
    points[i] = std::hypot(px[i], py[i]);
  }
}

struct Prepared {
  Plane huntL, huntA, huntB;  // Hunt-adjusted L*a*b* of the CSF-filtered image
  Plane edges, points;        // feature strengths of the unfiltered luminance
};

Prepared prepare(std::span<const glm::vec3> image, int w, int h, double ppd) {
  const std::size_t n = image.size();
  Plane yy(n), cx(n), cz(n), luminance(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 rgb(clamp01(image[i].x), clamp01(image[i].y), clamp01(image[i].z));
    const glm::dvec3 c = rgbToYcxcz(rgb);
    yy[i] = float(c.x);
    cx[i] = float(c.y);
    cz[i] = float(c.z);
    luminance[i] = float((c.x + 16.0) / 116.0);  // Y / Yn, in [0, 1]
  }
  const int radius = int(std::ceil(3.0 * std::sqrt(kCsfWidestB / (2.0 * kPi * kPi)) * ppd));
  const Plane fy = csfFilter(yy, w, h, kCsfAchromatic, ppd, radius);
  const Plane fx = csfFilter(cx, w, h, kCsfRedGreen, ppd, radius);
  const Plane fz = csfFilter(cz, w, h, kCsfBlueYellow, ppd, radius);
  Prepared p;
  p.huntL.resize(n);
  p.huntA.resize(n);
  p.huntB.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    // Filtering can leave the RGB cube; the paper clamps before the perceptual transform.
    glm::dvec3 rgb = ycxczToRgb(glm::dvec3(fy[i], fx[i], fz[i]));
    rgb = glm::clamp(rgb, 0.0, 1.0);
    const glm::dvec3 lab = rgbToHuntLab(rgb);
    p.huntL[i] = float(lab.x);
    p.huntA[i] = float(lab.y);
    p.huntB[i] = float(lab.z);
  }
  detectFeatures(luminance, w, h, featureKernels(ppd), p.edges, p.points);
  return p;
}

}  // namespace

double pixelsPerDegree(double distanceMetres, double widthMetres, double pixelsX) {
  return distanceMetres * (pixelsX / widthMetres) * (kPi / 180.0);
}

FlipResult flip(std::span<const glm::vec3> reference, std::span<const glm::vec3> test, int width,
                int height, double ppd) {
  if (width <= 0 || height <= 0 || !(ppd > 0.0))
    throw std::invalid_argument("flip: size and pixels per degree must be positive");
  const std::size_t n = std::size_t(width) * std::size_t(height);
  if (reference.size() != n || test.size() != n)
    throw std::invalid_argument("flip: images must hold width × height pixels");
  const Prepared r = prepare(reference, width, height, ppd);
  const Prepared t = prepare(test, width, height, ppd);
  // The largest colour distance in the gamut (Hunt-adjusted green vs blue), raised to qc.
  const double cMax =
      std::pow(hyab(rgbToHuntLab({0.0, 1.0, 0.0}), rgbToHuntLab({0.0, 0.0, 1.0})), kQc);
  const double knee = kPc * cMax;
  FlipResult result;
  result.error.resize(n);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double distance = std::pow(
        hyab({r.huntL[i], r.huntA[i], r.huntB[i]}, {t.huntL[i], t.huntA[i], t.huntB[i]}), kQc);
    // §4.1: small distances spread over [0, pt], the rarely reached rest over [pt, 1].
    const double colour = distance < knee ? kPt / knee * distance
                                          : kPt + (distance - knee) / (cMax - knee) * (1.0 - kPt);
    const double featureDelta = std::max(std::abs(double(r.edges[i]) - t.edges[i]),
                                         std::abs(double(r.points[i]) - t.points[i]));
    const double feature = std::pow(featureDelta / std::sqrt(2.0), kQf);
    const double e = std::clamp(std::pow(std::min(colour, 1.0), 1.0 - feature), 0.0, 1.0);
    result.error[i] = float(e);
    sum += e;
  }
  result.mean = sum / double(n);
  return result;
}

}  // namespace sdfstream::reference
