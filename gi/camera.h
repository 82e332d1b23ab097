// A pinhole camera in world space (double precision) and the primary rays it shoots, converted
// to cascade-relative floats (the GPU never sees world coordinates).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/frame_layout.h"
#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/view_raster_layout.h"
#include "streaming/cascade.h"

namespace sdfstream {

struct Camera {
  glm::dvec3 position{0.0, 0.0, 5.0};
  glm::dvec3 target{0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  double fovYDegrees = 50.0;
};

// "px,py,pz,tx,ty,tz[,fov]" -> Camera; std::nullopt when malformed.
std::optional<Camera> parseCamera(const std::string& text);
std::string formatCamera(const Camera& camera);

// A camera looking at the centre of [lo, hi] from the direction `from` (need not be unit),
// far enough that the bounding sphere fills the view.
Camera frameBounds(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& from,
                   double fovYDegrees = 50.0);
// The same, as close as the box [lo, hi] allows: looking at its centre from the direction
// `from`, near enough that its eight corners just fit a picture of `aspect` (width / height),
// so the box fills the view rather than its bounding sphere.
Camera frameBoxTightly(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& from,
                       double fovYDegrees, double aspect);

// One ray per pixel centre, row-major from the top-left pixel, in the cascade's voxel units.
std::vector<gpu_shared::TraceRay> primaryRays(const Camera& camera, int width, int height,
                                              const CascadeImage& cascade);
// Same, with the camera position already converted to the rays' frame (any frame whose axes are
// parallel to the world's with uniform scale, e.g. CascadeStackImage::toStack).
std::vector<gpu_shared::TraceRay> primaryRaysFrom(const Camera& camera, int width, int height,
                                                  const glm::vec3& originInRayFrame);

// The angle one pixel spans vertically (radians, at the centre): a surface's footprint per
// pixel is distance × this.
double cameraPixelAngle(const Camera& camera, int height);

// Clip from world for the rasterized view of the same pixels (shared/view_raster_layout.h:
// Vulkan clip space, reverse-Z, infinite far plane, near plane 1 mm): pixel (x, y)'s centre sees
// along primaryRaysFrom's ray (x, y).
gpu_shared::ViewRasterPush viewRasterPush(const Camera& camera, int width, int height);

// The push constants of camera_rays.comp for the same rays (shared/frame_layout.h), the camera
// at `originInRayFrame` (as primaryRaysFrom); no window (the caller sets windowLo/Hi).
gpu_shared::CameraRaysPush cameraRaysPush(const Camera& camera, int width, int height,
                                          const glm::vec3& originInRayFrame);

}  // namespace sdfstream
