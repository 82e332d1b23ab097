// Sampling's SDF visibility test runs only where Chebyshev leaves the answer open
// (probe_sample.glsl, probeSdfVisibilityPresumed). Against the test at every cage corner, on the
// same converged field: the irradiance of receivers on both sides of the walls of a closed room
// with one-voxel walls (the leak test's scene) must agree within stated tolerances, in the finest
// and the coarsest cascade and with the cascades blended, and skipping tests must never let more
// light into the room than the full test does.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "tests/probes/gi_harness.h"
#include "tests/probes/probe_field_checks.h"
#include "tests/support/analytic_stack.h"
#include "tests/support/gpu_test.h"

namespace sdfstream::probe {
namespace {

class ProbeSampleVisibilityTest : public test::GpuTest {};

constexpr std::uint32_t kGrey = 150u | 150u << 8 | 150u << 16 | 255u << 24;

double luminance(const glm::vec3& e) { return (e.x + e.y + e.z) / 3.0; }

// |a - b| per receiver in units of `scale` (the mean irradiance outside the room): its mean and
// 99th percentile, and the largest of a alone (a leak inside the closed room, same units).
struct Difference {
  double mean = 0.0, p99 = 0.0;
};

Difference compare(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                   std::size_t first, std::size_t last, double scale) {
  std::vector<double> d;
  for (std::size_t i = first; i < last; ++i)
    d.push_back(std::abs(luminance(a[i]) - luminance(b[i])) / scale);
  std::sort(d.begin(), d.end());
  Difference r;
  for (double x : d) r.mean += x / double(d.size());
  r.p99 = d[d.size() * 99 / 100];
  return r;
}

double worstInside(const std::vector<glm::vec3>& e, std::size_t first, std::size_t last,
                   double scale) {
  double worst = 0.0;
  for (std::size_t i = first; i < last; ++i) worst = std::max(worst, luminance(e[i]) / scale);
  return worst;
}

TEST_F(ProbeSampleVisibilityTest, SdfTestWhereUnsureMatchesTheTestAtEveryCorner) {
  const glm::vec3 lo(40.0f, 40.0f, 40.0f), hi(88.0f, 80.0f, 88.0f);
  auto inner = test::insideBox(lo, hi);
  auto outer = test::insideBox(lo - 1.0f, hi + 1.0f);
  auto shell = [&](glm::vec3 p, float scale) {
    return std::max(-outer(p), inner(p)) - 0.5f * (scale - 1.0f);
  };
  test::AnalyticStack room(3, shell, [](glm::vec3) { return glm::uvec2(kGrey, 0u); },
                           glm::vec3(64.0f));
  // Three fields with the same seed: the update never uses sampling's visibility rule, so they
  // hold the same probes; only sample() differs.
  ProbeFieldSettings gated;
  gated.raysPerProbe = 64;
  ProbeFieldSettings everywhere = gated;
  everywhere.sdfVisibilityWhereUnsure = false;
  ProbeFieldSettings chebyshevOnly = gated;
  chebyshevOnly.visibility = ProbeFieldSettings::Visibility::Chebyshev;
  std::vector<std::unique_ptr<test::GiHarness>> fields;
  for (const ProbeFieldSettings& s : {gated, everywhere, chebyshevOnly}) {
    fields.push_back(std::make_unique<test::GiHarness>(ctx(), s, 3, false, true));
    test::GiHarness& h = *fields.back();
    h.sky.zenith = glm::vec4(0.4f, 0.5f, 0.8f, 0.0f);
    h.sky.horizon = glm::vec4(0.6f, 0.6f, 0.6f, 0.0f);
    h.lights = test::sunLights(room.image, glm::vec3(-0.4f, -1.0f, -0.3f), 4.0f);
    ProbeFrameInputs in;
    in.cameraWorld = glm::dvec3(64.0, 60.0, 64.0);
    for (int frame = 0; frame < 8; ++frame) {
      in.lightsChanged = frame == 0;
      h.step(room.image, in, std::uint64_t(frame), frame == 0);
    }
  }
  // Receivers: half a voxel beyond every outer face, facing out (sunlit and sky-lit); then,
  // inside the closed room (where the true irradiance is 0), half a voxel in front of every inner
  // face facing in. (Points in the room's air are no test: in the coarsest cascade a receiver's
  // self-shadow bias of 0.75 spacings can carry it through the thickened wall, and both rules
  // then see outside light.)
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.1f, 0.9f);
  std::vector<gpu_shared::ProbeQuery> queries;
  const std::size_t outsideCount = 600, insideCount = 600;
  for (std::size_t i = 0; i < outsideCount + insideCount; ++i) {
    glm::vec3 p = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
    glm::vec3 n(0.0f);
    const int face = int(i % 6), axis = face / 2;
    const float sign = face % 2 == 0 ? 1.0f : -1.0f;  // into the room
    if (i < outsideCount) {
      n[axis] = -sign;
      p[axis] = sign > 0.0f ? lo[axis] - 1.5f : hi[axis] + 1.5f;
    } else {
      n[axis] = sign;
      p[axis] = sign > 0.0f ? lo[axis] + 0.5f : hi[axis] - 0.5f;
    }
    queries.push_back({glm::vec4(p, 0.0f), glm::vec4(n, 0.0f), glm::vec4(n, 0.0f)});
  }
  const std::size_t all = queries.size();
  for (int cascade : {-1, 0, 2}) {
    for (auto& q : queries) q.position.w = float(cascade + 1);
    const auto eGated = fields[0]->sampleGpu(queries);
    const auto eEverywhere = fields[1]->sampleGpu(queries);
    const auto eChebyshev = fields[2]->sampleGpu(queries);
    double outsideMean = 0.0;
    for (std::size_t i = 0; i < outsideCount; ++i)
      outsideMean += luminance(eEverywhere[i]) / double(outsideCount);
    const Difference out = compare(eGated, eEverywhere, 0, outsideCount, outsideMean);
    const Difference in = compare(eGated, eEverywhere, outsideCount, all, outsideMean);
    const double leakGated = worstInside(eGated, outsideCount, all, outsideMean);
    const double leakEverywhere = worstInside(eEverywhere, outsideCount, all, outsideMean);
    const double leakChebyshev = worstInside(eChebyshev, outsideCount, all, outsideMean);
    std::printf("[figures] SDF test where unsure vs at every corner, %s (units: mean outside "
                "irradiance %.4f): outside receivers |diff| mean %.5f, 99th percentile %.5f; "
                "inside |diff| mean %.5f, 99th percentile %.5f; worst inside irradiance: where "
                "unsure %.5f, every corner %.5f, Chebyshev alone %.5f\n",
                cascade < 0 ? "cascades blended" : ("cascade " + std::to_string(cascade)).c_str(),
                outsideMean, out.mean, out.p99, in.mean, in.p99, leakGated, leakEverywhere,
                leakChebyshev);
    EXPECT_GT(outsideMean, 0.1);
    EXPECT_LE(out.mean, 0.01) << "cascade " << cascade;
    EXPECT_LE(out.p99, 0.05) << "cascade " << cascade;
    EXPECT_LE(in.p99, 0.01) << "cascade " << cascade;
    // Skipping tests must never open a leak the full test closes.
    EXPECT_LE(leakGated, leakEverywhere + 0.01) << "cascade " << cascade;
  }
}

}  // namespace
}  // namespace sdfstream::probe
