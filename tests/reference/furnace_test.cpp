// White furnace and convergence: the reference against the analytic value of a white furnace,
// and its error falling as 1/√samples.
//
// In a closed box whose walls all emit Le and reflect with albedo ρ, the radiance is the same
// everywhere and in every direction: L = Le + ρ·L, so L = Le / (1 − ρ), and the irradiance at any
// interior point, for any normal, is
//     E = π·L = π·Le / (1 − ρ)                               (Total)
//     E_indirect = E − π·Le = π·Le·ρ / (1 − ρ)                (IndirectOnly: minus what x sees
//                                                              emitted directly)
// Every path carries the exact expected value except for Russian roulette, so the estimator's
// spread comes from roulette alone and its mean must land on the formula.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "reference/path_tracer.h"
#include "tests/reference/test_scenes.h"

namespace sdfstream::reference {
namespace {

constexpr float kPi = 3.14159265358979f;
const glm::vec3 kLo(-1.0f, 0.0f, -2.0f), kHi(2.0f, 2.5f, 1.0f);  // not a cube, not at the origin
const glm::vec3 kAlbedo(0.3f, 0.5f, 0.7f);
const glm::vec3 kEmission(1.0f, 2.0f, 0.5f);

glm::vec3 furnaceTotal() { return kPi * kEmission / (glm::vec3(1.0f) - kAlbedo); }

TEST(Furnace, TotalIrradianceMatchesPiLeOverOneMinusAlbedo) {
  const TriangleScene box = test::closedBox(kLo, kHi, kAlbedo, kEmission);
  const PathTracer tracer(box, SceneLights{});
  test::SurfacePoints points = test::boxWallPoints(kLo, kHi, 30);
  // Interior points off the walls, with arbitrary normals: E must not depend on either.
  points.positions.push_back({0.5f, 1.2f, -0.5f});
  points.normals.push_back(glm::normalize(glm::vec3(1.0f, 2.0f, -0.5f)));
  points.positions.push_back({-0.7f, 0.3f, 0.6f});
  points.normals.push_back(glm::normalize(glm::vec3(-0.3f, -1.0f, 0.2f)));
  const std::uint32_t samples = 65536;  // the 0.7 channel needs it for a 1% bound
  const auto e =
      tracer.irradiance(points.positions, points.normals, samples, IrradianceKind::Total);
  const glm::vec3 expected = furnaceTotal();
  int outsideCi = 0;
  double worstRel = 0.0, meanHalfRel = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    EXPECT_EQ(e[i].samples, samples);
    for (int c = 0; c < 3; ++c) {
      const double err = std::abs(double(e[i].mean[c]) - expected[c]);
      worstRel = std::max(worstRel, err / expected[c]);
      meanHalfRel += e[i].halfWidth95[c] / expected[c] / (3.0 * double(e.size()));
      EXPECT_LT(err, 0.01 * expected[c]) << "point " << i << " channel " << c;
      EXPECT_GT(e[i].halfWidth95[c], 0.0f);  // roulette makes a spread; zero would be a bug
      if (err > e[i].halfWidth95[c]) ++outsideCi;
    }
  }
  // A 95% interval misses 5% of the time: of 96 (point, channel) pairs about 5 may fall
  // outside; 13 or more has probability < 0.1% if the intervals are right.
  EXPECT_LE(outsideCi, 12);
  std::printf(
      "furnace: E = (%.4f %.4f %.4f), worst relative error %.4f%%, mean 95%% half-width "
      "%.4f%%, %d of %zu outside their CI\n",
      expected.x, expected.y, expected.z, 100.0 * worstRel, 100.0 * meanHalfRel, outsideCi,
      3 * e.size());
}

TEST(Furnace, IndirectOnlyExcludesEmissionSeenDirectly) {
  const TriangleScene box = test::closedBox(kLo, kHi, kAlbedo, kEmission);
  const PathTracer tracer(box, SceneLights{});
  const test::SurfacePoints points = test::boxWallPoints(kLo, kHi, 12);
  const auto e =
      tracer.irradiance(points.positions, points.normals, 65536, IrradianceKind::IndirectOnly);
  const glm::vec3 expected = kPi * kEmission * kAlbedo / (glm::vec3(1.0f) - kAlbedo);
  double worstRel = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double err = std::abs(double(e[i].mean[c]) - expected[c]);
      worstRel = std::max(worstRel, err / expected[c]);
      EXPECT_LT(err, 0.01 * expected[c]) << "point " << i << " channel " << c;
      EXPECT_LT(err, 1.5 * e[i].halfWidth95[c]) << "point " << i << " channel " << c;
    }
  std::printf("furnace, indirect only: worst relative error %.4f%%\n", 100.0 * worstRel);
  // With no delta lights NoDirectLights is Total.
  const auto all =
      tracer.irradiance(points.positions, points.normals, 256, IrradianceKind::NoDirectLights);
  const auto total =
      tracer.irradiance(points.positions, points.normals, 256, IrradianceKind::Total);
  for (std::size_t i = 0; i < e.size(); ++i) EXPECT_EQ(all[i].mean, total[i].mean);
}

// A box with a gap: light leaks out, so the furnace value must NOT be reached. Guards against a
// furnace test that passes whatever the geometry (e.g. if misses returned the furnace radiance).
TEST(Furnace, OpenBoxFallsShortOfTheClosedValue) {
  TriangleScene box = test::closedBox(kLo, kHi, kAlbedo, kEmission);
  box.triangles.resize(10);  // drop the last face (two triangles)
  box.triangleMaterial.resize(10);
  const PathTracer tracer(box, SceneLights{});
  const test::SurfacePoints points = test::boxWallPoints(kLo, kHi, 6);
  const auto e = tracer.irradiance(points.positions, points.normals, 1024, IrradianceKind::Total);
  for (const auto& est : e)
    for (int c = 0; c < 3; ++c) EXPECT_LT(est.mean[c], 0.97f * furnaceTotal()[c]);
}

// RMS error against the analytic value over N = 64 … 4096 samples: the log-log slope must be
// about −1/2, and the reported 95% half-width must shrink by √(4096/64) = 8.
TEST(Furnace, ErrorFallsAsOneOverSqrtSamples) {
  const TriangleScene box = test::closedBox(kLo, kHi, kAlbedo, kEmission);
  const test::SurfacePoints points = test::boxWallPoints(kLo, kHi, 96);
  const glm::vec3 expected = furnaceTotal();
  std::vector<double> logN, logErr, meanHalf;
  for (std::uint32_t n = 64, level = 0; n <= 4096; n *= 2, ++level) {
    PathTracerSettings settings;
    settings.seed = 1000 + level;  // independent estimates per level
    const PathTracer tracer(box, SceneLights{}, settings);
    const auto e = tracer.irradiance(points.positions, points.normals, n, IrradianceKind::Total);
    double sq = 0.0, half = 0.0;
    for (const auto& est : e)
      for (int c = 0; c < 3; ++c) {
        const double rel = (est.mean[c] - expected[c]) / expected[c];
        sq += rel * rel;
        half += est.halfWidth95[c] / expected[c];
      }
    const double count = 3.0 * double(e.size());
    logN.push_back(std::log(double(n)));
    logErr.push_back(0.5 * std::log(sq / count));
    meanHalf.push_back(half / count);
    std::printf("convergence: N = %4u  RMS relative error %.5f  mean 95%% half-width %.5f\n", n,
                std::exp(logErr.back()), meanHalf.back());
  }
  // Least-squares slope of log error against log N.
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < logN.size(); ++i) mx += logN[i], my += logErr[i];
  mx /= double(logN.size());
  my /= double(logN.size());
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < logN.size(); ++i) {
    sxy += (logN[i] - mx) * (logErr[i] - my);
    sxx += (logN[i] - mx) * (logN[i] - mx);
  }
  const double slope = sxy / sxx;
  std::printf("convergence: slope of log RMS error vs log N = %.3f\n", slope);
  EXPECT_GT(slope, -0.65);
  EXPECT_LT(slope, -0.35);
  const double ratio = meanHalf.front() / meanHalf.back();
  EXPECT_NEAR(ratio, 8.0, 0.8) << "half-width(64) / half-width(4096)";
}

}  // namespace
}  // namespace sdfstream::reference
