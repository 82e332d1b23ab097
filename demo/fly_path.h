// Camera paths for fly-throughs: a Catmull-Rom spline through waypoints, sampled at constant
// speed (arc length), with the camera looking along the path.
#pragma once

#include <filesystem>
#include <vector>

#include <glm/glm.hpp>

#include "gi/camera.h"

namespace sdfstream {

struct FlyPath {
  std::vector<glm::dvec3> waypoints;  // world metres, at least 2

  // Total length (metres), by dense sampling of the spline.
  double length() const;
  // Position at arc length s (clamped to [0, length()]) and the unit direction of travel there.
  glm::dvec3 position(double s) const;
  glm::dvec3 direction(double s) const;
};

// Reads waypoints, one "x y z" (or "x,y,z") per line; '#' starts a comment. Throws InputError
// naming the file and line.
FlyPath readFlyPath(const std::filesystem::path& file);

// A default route over a world's bounds: a gentle S across the longest horizontal axis at a
// height a little above the middle of the bounds.
FlyPath defaultFlyPath(const glm::dvec3& boundsMin, const glm::dvec3& boundsMax);

// The fly-through's camera at arc length s: on the path, looking along it and a little down
// (the ground ahead stays in view), 60 degrees vertical field of view.
Camera pathCamera(const FlyPath& path, double s);

}  // namespace sdfstream
