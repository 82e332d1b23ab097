#include "reference/path_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "reference/sampling.h"
#include "shaders/shared/light_layout.h"  // kMaxLights: the reference takes what the GI can

namespace sdfstream::reference {
namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInf = std::numeric_limits<float>::infinity();
// Render streams use other keys than irradiance() streams so that a render and a point query of
// the same scene and seed are not correlated.
constexpr std::uint64_t kRenderStream = 0x52454e4445520000ull;  // "RENDER"

float maxComponent(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

float smoothstep(float edge0, float edge1, float x) {
  if (edge1 <= edge0) return x >= edge1 ? 1.0f : 0.0f;  // degenerate cone: hard edge
  const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// Per-channel running mean and variance (Welford), in double so that 10⁶ samples of fp32 path
// values do not lose the variance to cancellation.
struct RunningStats {
  glm::dvec3 mean{0.0};
  glm::dvec3 m2{0.0};
  std::uint32_t n = 0;
  void add(const glm::vec3& x) {
    ++n;
    const glm::dvec3 d = glm::dvec3(x) - mean;
    mean += d / double(n);
    m2 += d * (glm::dvec3(x) - mean);
  }
  IrradianceEstimate estimate() const {
    IrradianceEstimate e;
    e.samples = n;
    e.mean = glm::vec3(mean);
    if (n > 1) e.halfWidth95 = glm::vec3(1.96 * glm::sqrt(m2 / double(n - 1) / double(n)));
    return e;
  }
};

}  // namespace

PathTracer::PathTracer(const TriangleScene& scene, const SceneLights& lights,
                       PathTracerSettings settings)
    : scene_(scene), lights_(lights), settings_(settings), embree_(scene) {
  if (lights_.lights.size() > gpu_shared::kMaxLights)
    throw std::invalid_argument("PathTracer: " + std::to_string(lights_.lights.size()) +
                                " lights; at most " + std::to_string(gpu_shared::kMaxLights));
  if (settings_.maxDepth == 0) throw std::invalid_argument("PathTracer: maxDepth must be >= 1");
  // Float spacing grows with the coordinates' magnitude: 1e-5 of the largest one is ~80 ulps,
  // enough to leave the surface, and 1 mm in a 100 m scene, small enough not to skip contacts.
  const glm::vec3 extent = glm::max(glm::abs(scene.boundsMin()), glm::abs(scene.boundsMax()));
  epsilon_ = 1e-5f * std::max(1.0f, maxComponent(extent));
}

glm::vec3 PathTracer::skyRadiance(const glm::vec3& dir) const {
  return glm::mix(lights_.sky.horizon, lights_.sky.zenith, std::clamp(dir.y, 0.0f, 1.0f));
}

// Irradiance at x from the delta lights (next-event estimation): exact, one shadow ray each.
glm::vec3 PathTracer::directLights(const glm::vec3& x, const glm::vec3& n) const {
  glm::vec3 sum(0.0f);
  const glm::vec3 origin = x + n * epsilon_;
  for (const SceneLight& light : lights_.lights) {
    const glm::vec3 radiant = light.color * light.intensity;
    if (light.type == SceneLight::Type::Sun) {
      const glm::vec3 toLight = -glm::normalize(light.direction);
      const float cosTheta = glm::dot(n, toLight);
      if (cosTheta <= 0.0f) continue;
      if (light.castsShadows && embree_.occluded(origin, toLight, 0.0f, kInf)) continue;
      sum += radiant * cosTheta;
      continue;
    }
    const glm::vec3 toLightVec = glm::vec3(light.position) - x;
    const float d2 = glm::dot(toLightVec, toLightVec);
    if (d2 <= 1e-12f) continue;
    const float d = std::sqrt(d2);
    const glm::vec3 toLight = toLightVec / d;
    const float cosTheta = glm::dot(n, toLight);
    if (cosTheta <= 0.0f) continue;
    float window = 1.0f;
    if (light.range > 0.0f) {
      const float r = d / light.range;
      const float w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
      window = w * w;
    }
    if (light.type == SceneLight::Type::Spot) {
      const float toRad = kPi / 180.0f;
      const float cosAxis = glm::dot(-toLight, glm::normalize(light.direction));
      window *= smoothstep(std::cos(light.outerConeDegrees * toRad),
                           std::cos(light.innerConeDegrees * toRad), cosAxis);
    }
    if (window <= 0.0f) continue;
    if (light.castsShadows) {
      const float tMax = glm::length(glm::vec3(light.position) - origin) - epsilon_;
      if (tMax > 0.0f && embree_.occluded(origin, toLight, 0.0f, tMax)) continue;
    }
    sum += radiant * (cosTheta * window / d2);
  }
  return sum;
}

// One sample of E(x, n): the delta lights at x (Total only) plus π × the radiance carried by one
// cosine-weighted path (pdf cos/π, so ∫ L cos dω ≈ π·L).
glm::vec3 PathTracer::sampleIrradiance(const glm::vec3& x, const glm::vec3& n, IrradianceKind kind,
                                       SampleRng& rng) const {
  glm::vec3 direct(0.0f);
  if (kind == IrradianceKind::Total) direct = directLights(x, n);
  const bool countSeenDirectly = kind != IrradianceKind::IndirectOnly;

  glm::vec3 origin = x + n * epsilon_;
  glm::vec3 dir = cosineHemisphere(n, rng.uniform(), rng.uniform());
  glm::vec3 throughput(1.0f);
  glm::vec3 radiance(0.0f);
  for (std::uint32_t depth = 1;; ++depth) {
    // depth 1 is the segment that ends at x: what it carries (sky, emission) is length 1.
    const bool seenDirectly = depth == 1;
    const auto hit = embree_.intersect(origin, dir, 0.0f, kInf);
    if (!hit) {
      if (countSeenDirectly || !seenDirectly) radiance += throughput * skyRadiance(dir);
      break;
    }
    const glm::vec3 y = origin + dir * hit->t;
    const glm::vec3 ng = glm::dot(hit->normal, dir) > 0.0f ? -hit->normal : hit->normal;
    if (countSeenDirectly || !seenDirectly)
      radiance += throughput * sampleEmission(scene_, hit->triangle, hit->bary);
    const glm::vec3 albedo =
        glm::clamp(glm::vec3(sampleAlbedo(scene_, hit->triangle, hit->bary)), 0.0f, 1.0f);
    throughput *= albedo;
    if (maxComponent(throughput) <= 0.0f) break;
    // Lights reflected at y reach x by a path of length >= 2: counted for every kind.
    if (!lights_.lights.empty()) radiance += throughput * (directLights(y, ng) / kPi);
    if (depth >= settings_.maxDepth) break;
    if (depth >= settings_.rrStartDepth) {
      const float survive = std::min(0.95f, maxComponent(throughput));
      if (rng.uniform() >= survive) break;
      throughput /= survive;
    }
    origin = y + ng * epsilon_;
    dir = cosineHemisphere(ng, rng.uniform(), rng.uniform());
  }
  return direct + kPi * radiance;
}

std::vector<IrradianceEstimate> PathTracer::irradiance(std::span<const glm::vec3> positions,
                                                       std::span<const glm::vec3> normals,
                                                       std::uint32_t samples,
                                                       IrradianceKind kind) const {
  if (positions.size() != normals.size())
    throw std::invalid_argument("PathTracer::irradiance: positions and normals differ in length");
  std::vector<IrradianceEstimate> out(positions.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const glm::vec3 n = glm::normalize(normals[i]);
                        RunningStats stats;
                        for (std::uint32_t s = 0; s < samples; ++s) {
                          SampleRng rng(settings_.seed, i, s);
                          stats.add(sampleIrradiance(positions[i], n, kind, rng));
                        }
                        out[i] = stats.estimate();
                      }
                    });
  return out;
}

glm::vec3 PathTracer::primaryDirection(const PinholeCamera& camera, int width, int height, float px,
                                       float py) const {
  const glm::vec3 forward = glm::normalize(camera.forward);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tanHalf = std::tan(camera.verticalFovDegrees * kPi / 360.0f);
  const float aspect = float(width) / float(height);
  const float sx = (2.0f * px / float(width) - 1.0f) * tanHalf * aspect;
  const float sy = (1.0f - 2.0f * py / float(height)) * tanHalf;
  return glm::normalize(forward + sx * right + sy * up);
}

RadianceImage PathTracer::render(const PinholeCamera& camera, int width, int height,
                                 std::uint32_t spp, IrradianceKind kind) const {
  if (width <= 0 || height <= 0) throw std::invalid_argument("PathTracer::render: empty image");
  RadianceImage image;
  image.width = width;
  image.height = height;
  image.pixels.assign(std::size_t(width) * std::size_t(height), glm::vec3(0.0f));
  const std::uint64_t seed = mix64(settings_.seed ^ kRenderStream);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, image.pixels.size()),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t p = range.begin(); p != range.end(); ++p) {
          const int px = int(p % std::size_t(width)), py = int(p / std::size_t(width));
          glm::dvec3 sum(0.0);
          for (std::uint32_t s = 0; s < spp; ++s) {
            SampleRng rng(seed, p, s);
            const float jx = rng.uniform(), jy = rng.uniform();
            const glm::vec3 dir =
                primaryDirection(camera, width, height, float(px) + jx, float(py) + jy);
            const auto hit = embree_.intersect(camera.position, dir, 0.0f, kInf);
            if (!hit) {
              if (kind == IrradianceKind::Total) sum += glm::dvec3(skyRadiance(dir));
              continue;
            }
            const glm::vec3 y = camera.position + dir * hit->t;
            const glm::vec3 ng = glm::dot(hit->normal, dir) > 0.0f ? -hit->normal : hit->normal;
            const glm::vec3 albedo =
                glm::clamp(glm::vec3(sampleAlbedo(scene_, hit->triangle, hit->bary)), 0.0f, 1.0f);
            glm::vec3 radiance = albedo / kPi * sampleIrradiance(y, ng, kind, rng);
            if (kind == IrradianceKind::Total)
              radiance += sampleEmission(scene_, hit->triangle, hit->bary);
            sum += glm::dvec3(radiance);
          }
          image.pixels[p] = spp > 0 ? glm::vec3(sum / double(spp)) : glm::vec3(0.0f);
        }
      });
  return image;
}

std::vector<VisiblePoint> PathTracer::visiblePoints(const PinholeCamera& camera, int width,
                                                    int height) const {
  if (width <= 0 || height <= 0) return {};
  std::vector<VisiblePoint> out(std::size_t(width) * std::size_t(height));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size()),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t p = range.begin(); p != range.end(); ++p) {
                        const float px = float(p % std::size_t(width)) + 0.5f;
                        const float py = float(p / std::size_t(width)) + 0.5f;
                        const glm::vec3 dir = primaryDirection(camera, width, height, px, py);
                        const auto hit = embree_.intersect(camera.position, dir, 0.0f, kInf);
                        if (!hit) continue;
                        out[p].hit = true;
                        out[p].position = camera.position + dir * hit->t;
                        out[p].normal =
                            glm::dot(hit->normal, dir) > 0.0f ? -hit->normal : hit->normal;
                      }
                    });
  return out;
}

}  // namespace sdfstream::reference
