#include "world/cornell_light.h"

#include <algorithm>

#include "core/error.h"

namespace sdfstream {

SceneLight cornellSpotFromEmitters(TriangleScene& s, float shadowSharpness) {
  glm::dvec3 centre(0.0), emitted(0.0);
  double area = 0.0;
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const Material& m = s.materials[s.triangleMaterial[t]];
    if (glm::length(m.emissive) <= 0.0f) continue;
    const glm::dvec3 a = s.positions[s.triangles[t].x], b = s.positions[s.triangles[t].y],
                     c = s.positions[s.triangles[t].z];
    const double A = 0.5 * glm::length(glm::cross(b - a, c - a));
    centre += A * (a + b + c) / 3.0;
    emitted += A * glm::dvec3(m.emissive);
    area += A;
  }
  if (area <= 0.0)
    throw InputError(InputErrorKind::MissingData, s.source, "no emissive ceiling light found");
  centre /= area;
  const glm::vec3 ke = glm::vec3(emitted / area);  // area-weighted emission (radiance)
  for (Material& m : s.materials) m.emissive = glm::vec3(0.0f);
  const double height = double(s.boundsMax().y - s.boundsMin().y);
  SceneLight spot;
  spot.type = SceneLight::Type::Spot;
  spot.position = centre - glm::dvec3(0.0, 0.025 * height, 0.0);
  spot.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  const float peak = std::max({ke.x, ke.y, ke.z});
  spot.color = ke / peak;
  spot.intensity = peak * float(area);  // on-axis intensity of a Lambertian quad: L·A
  spot.innerConeDegrees = 0.0f;
  spot.outerConeDegrees = 90.0f;  // smoothstep(cos 90, cos 0, cos θ): a cosine-like falloff
  spot.shadowSharpness = shadowSharpness;
  return spot;
}

}  // namespace sdfstream
