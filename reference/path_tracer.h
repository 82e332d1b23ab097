// Monte Carlo path tracer on the source triangles: the ground truth the GI is judged by. It sees
// the same scene as the GI — TriangleScene materials (linear albedo and emission via sampleAlbedo /
// sampleEmission) and the SceneLights lights and sky (world/scene_lights.h, semantics in
// shaders/shared/light_layout.h) — and is built on Embree, which no one here wrote.
//
// Model:
//  - Lambertian surfaces only, two-sided: at every hit the geometric normal is turned towards
//    the incoming ray. Albedo is clamped to [0, 1] (energy conserving); alpha is ignored.
//  - Delta lights by next-event estimation with hard shadows (a light with castsShadows = false
//    casts none). The GI's soft-shadow sharpness is an approximation the reference does not make.
//      sun:   E = I·color·cos θ                   (θ between normal and the way to the light)
//      point: E = I·color·cos θ / d² · W(d)       (d in metres)
//      spot:  point × smoothstep(cosOuter, cosInner, cos of the angle to the spot axis)
//      W(d) = clamp(1 − (d/range)⁴, 0, 1)² when range > 0, else 1 (Karis 2013, "Real Shading in
//      Unreal Engine 4": reaches zero exactly at `range` with zero slope; the same window and
//      spot step as shaders/light_math.glsl).
//  - Sky on rays that hit nothing: L(ω) = mix(horizon, zenith, clamp(ω.y, 0, 1)).
//  - Cosine-weighted hemisphere sampling; Russian roulette from rrStartDepth on (unbiased:
//    survivors are divided by the survival probability); paths stop at maxDepth surface hits
//    (a truncation bias of about albedo^maxDepth, below 1e-6 for albedo 0.8 and the default).
//
// Kinds of irradiance E(x, n) = ∫ L_in(x, ω) cos θ dω at a point x with unit normal n. Path
// length counts segments from the light to x: light seen directly by x is length 1.
//  - Total:        all incoming light: the delta lights at x, emission and sky seen from x, and
//                  every bounce.
//  - IndirectOnly: "diffuse indirect": paths of length ≥ 2, i.e. light that was reflected by at
//                  least one surface before reaching x. Excludes the delta lights at x and the
//                  emission and sky that x sees directly.
//  - NoDirectLights: Total minus the delta lights' direct term at x (emission and sky seen
//                  directly are kept): what a probe volume stores when the direct lights are
//                  shaded separately, as in DDGI.
//
// Thread safety: const methods may be called from any thread; each call itself runs in parallel
// with TBB over points (or pixels). Results are bit-identical for the same seed whatever the
// thread count (reference/sampling.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "reference/embree_scene.h"
#include "world/scene_lights.h"
#include "world/triangle_scene.h"

namespace sdfstream::reference {

class SampleRng;  // reference/sampling.h

enum class IrradianceKind : std::uint32_t {
  Total = 0,           // all incoming light
  IndirectOnly = 1,    // paths of length ≥ 2 (light that bounced at least once)
  NoDirectLights = 2,  // Total minus the delta lights' direct term at the point
};

struct PathTracerSettings {
  std::uint32_t maxDepth = 64;     // surface hits after the query point; ≥ 1
  std::uint32_t rrStartDepth = 3;  // Russian roulette from this many hits on
  std::uint64_t seed = 1;          // with (point, sample) keys every random number
};

struct IrradianceEstimate {
  glm::vec3 mean{0.0f};         // E(x, n), linear RGB (a sun of intensity I facing x gives I)
  glm::vec3 halfWidth95{0.0f};  // 1.96·s/√N per channel (normal approximation of the mean's
                                // 95% confidence interval; optimistic for heavy-tailed paths)
  std::uint32_t samples = 0;
};

// A pinhole camera in world metres. Pixel (0, 0) is the top-left; +x of the image is
// cross(forward, up).
struct PinholeCamera {
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // need not be unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // need not be unit or orthogonal to forward
  float verticalFovDegrees = 60.0f;
};

// Linear RGB, rows top to bottom.
struct RadianceImage {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> pixels;  // width × height
};

// The surface seen through a pixel centre (for relMSE of irradiance at visible points).
struct VisiblePoint {
  glm::vec3 position{0.0f};  // world metres, on the triangle
  glm::vec3 normal{0.0f};    // unit geometric normal, turned towards the camera
  bool hit = false;          // false: the pixel sees the sky; position/normal are zero
};

class PathTracer {
 public:
  // Builds the Embree scene. `scene` must outlive the tracer (materials and textures are read
  // from it at every hit); `lights` is copied. Throws std::invalid_argument for more than
  // gpu_shared::kMaxLights lights or maxDepth = 0.
  PathTracer(const TriangleScene& scene, const SceneLights& lights,
             PathTracerSettings settings = {});

  // Irradiance at positions[i] over the hemisphere of normals[i] (non-zero; normalised here),
  // `samples`
  // hemisphere paths each. Points should lie on (or just off) a surface; rays start a small
  // offset along the normal. Point i uses random keys (seed, i, s), so splitting a query changes
  // its numbers. Throws std::invalid_argument when the spans differ in length.
  std::vector<IrradianceEstimate> irradiance(std::span<const glm::vec3> positions,
                                             std::span<const glm::vec3> normals,
                                             std::uint32_t samples, IrradianceKind kind) const;

  // Outgoing diffuse radiance of the surfaces a camera sees, `spp` jittered paths per pixel:
  //  - Total: emission + albedo/π · E_total at the first hit; sky radiance where nothing is hit
  //    (what a camera records);
  //  - IndirectOnly / NoDirectLights: albedo/π · E_kind at the first hit; 0 where nothing is hit.
  RadianceImage render(const PinholeCamera& camera, int width, int height, std::uint32_t spp,
                       IrradianceKind kind) const;

  // First hits through the pixel centres of the same camera model as render().
  std::vector<VisiblePoint> visiblePoints(const PinholeCamera& camera, int width, int height) const;

  // The delta lights' irradiance at x (world metres) on unit normal n, hard shadows (next-event
  // estimation of one path vertex), and the sky's radiance along unit dir: the two ends of a
  // one-bounce path, for comparisons ray by ray.
  glm::vec3 directIrradiance(const glm::vec3& x, const glm::vec3& n) const {
    return directLights(x, n);
  }
  glm::vec3 skyRadianceAlong(const glm::vec3& dir) const { return skyRadiance(dir); }

  const TriangleScene& scene() const { return scene_; }
  const SceneLights& lights() const { return lights_; }
  const PathTracerSettings& settings() const { return settings_; }

 private:
  glm::vec3 sampleIrradiance(const glm::vec3& x, const glm::vec3& n, IrradianceKind kind,
                             SampleRng& rng) const;
  glm::vec3 directLights(const glm::vec3& x, const glm::vec3& n) const;
  glm::vec3 skyRadiance(const glm::vec3& dir) const;
  glm::vec3 primaryDirection(const PinholeCamera& camera, int width, int height, float px,
                             float py) const;

  const TriangleScene& scene_;
  SceneLights lights_;
  PathTracerSettings settings_;
  EmbreeScene embree_;
  float epsilon_;  // ray offset: scaled to the scene's coordinates so it beats float rounding
};

}  // namespace sdfstream::reference
