#include "gi/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace sdfstream {

std::optional<Camera> parseCamera(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    double d = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(d)) return std::nullopt;
    v.push_back(d);
  }
  if (v.size() != 6 && v.size() != 7) return std::nullopt;
  Camera c;
  c.position = {v[0], v[1], v[2]};
  c.target = {v[3], v[4], v[5]};
  if (v.size() == 7) c.fovYDegrees = v[6];
  if (glm::length(c.target - c.position) <= 0.0 || c.fovYDegrees <= 1.0 || c.fovYDegrees >= 170.0)
    return std::nullopt;
  return c;
}

std::string formatCamera(const Camera& c) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.1f", c.position.x, c.position.y,
                c.position.z, c.target.x, c.target.y, c.target.z, c.fovYDegrees);
  return buf;
}

Camera frameBounds(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& from,
                   double fovYDegrees) {
  Camera c;
  c.target = 0.5 * (lo + hi);
  double radius = 0.5 * glm::length(hi - lo);
  double distance = radius / std::sin(glm::radians(fovYDegrees) * 0.5) * 1.05;
  c.position = c.target + glm::normalize(from) * distance;
  c.fovYDegrees = fovYDegrees;
  return c;
}

Camera frameBoxTightly(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& from,
                       double fovYDegrees, double aspect) {
  Camera c;
  c.target = 0.5 * (lo + hi);
  c.fovYDegrees = fovYDegrees;
  // The camera's axes as primaryRaysFrom builds them (world up, looking at the target).
  const glm::dvec3 back = glm::normalize(from);
  const glm::dvec3 right = glm::normalize(glm::cross(c.up, back));
  const glm::dvec3 up = glm::cross(back, right);
  const double tanY = std::tan(glm::radians(fovYDegrees) * 0.5), tanX = tanY * aspect;
  // A corner at (x, y) across the view and z towards the camera is in view from distance D
  // when |x| <= (D - z) tanX and |y| <= (D - z) tanY.
  double distance = 0.0;
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 corner(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    const glm::dvec3 d = corner - c.target;
    const double z = glm::dot(d, back);
    distance = std::max(
        {distance, z + std::abs(glm::dot(d, right)) / tanX, z + std::abs(glm::dot(d, up)) / tanY});
  }
  c.position = c.target + back * distance * 1.02;
  return c;
}

std::vector<gpu_shared::TraceRay> primaryRays(const Camera& camera, int width, int height,
                                              const CascadeImage& cascade) {
  return primaryRaysFrom(camera, width, height, cascade.toCascade(camera.position));
}

namespace {
// The camera's frame as the primary rays use it: forward, right and up, orthonormal.
struct CameraFrame {
  glm::dvec3 forward, right, up;
};
CameraFrame cameraFrame(const Camera& camera) {
  CameraFrame f;
  f.forward = glm::normalize(camera.target - camera.position);
  const glm::dvec3 upHint =
      std::abs(glm::dot(f.forward, camera.up)) > 0.999 ? glm::dvec3(0, 0, 1) : camera.up;
  f.right = glm::normalize(glm::cross(f.forward, upHint));
  f.up = glm::cross(f.right, f.forward);
  return f;
}
}  // namespace

std::vector<gpu_shared::TraceRay> primaryRaysFrom(const Camera& camera, int width, int height,
                                                  const glm::vec3& origin) {
  const auto [forward, right, up] = cameraFrame(camera);
  double tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5);
  double aspect = double(width) / double(height);
  std::vector<gpu_shared::TraceRay> rays(std::size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double u = (2.0 * (x + 0.5) / width - 1.0) * tanHalf * aspect;
      double v = (1.0 - 2.0 * (y + 0.5) / height) * tanHalf;
      // World and cascade axes are parallel with uniform scale, so directions carry over.
      glm::vec3 dir(glm::normalize(forward + u * right + v * up));
      auto& r = rays[std::size_t(y) * width + x];
      r.originTMin = glm::vec4(origin, 0.0f);
      r.dirTMax = glm::vec4(dir, 1e30f);
    }
  return rays;
}

double cameraPixelAngle(const Camera& camera, int height) {
  return 2.0 * std::tan(glm::radians(camera.fovYDegrees) * 0.5) / double(height);
}

gpu_shared::ViewRasterPush viewRasterPush(const Camera& camera, int width, int height) {
  // Ray (x, y) points along forward + u·right + v·up with u = ndcX·tanHalf·aspect and
  // v = -ndcY·tanHalf (Vulkan's y points down): so ndcX = x_view / (z_view·tanHalf·aspect),
  // ndcY = -y_view / (z_view·tanHalf), and depth = near / z_view (reverse-Z, infinite far).
  constexpr double kNear = 1e-3;
  const CameraFrame f = cameraFrame(camera);
  const double tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5);
  const double aspect = double(width) / double(height);
  auto row = [&](const glm::dvec3& axis, double scale) {
    return glm::vec4(glm::vec3(axis * scale), float(-glm::dot(axis, camera.position) * scale));
  };
  gpu_shared::ViewRasterPush push{};
  push.clipFromWorld[0] = row(f.right, 1.0 / (tanHalf * aspect));
  push.clipFromWorld[1] = row(f.up, -1.0 / tanHalf);
  push.clipFromWorld[2] = glm::vec4(0.0f, 0.0f, 0.0f, float(kNear));
  push.clipFromWorld[3] = row(f.forward, 1.0);
  return push;
}

gpu_shared::CameraRaysPush cameraRaysPush(const Camera& camera, int width, int height,
                                          const glm::vec3& originInRayFrame) {
  const CameraFrame f = cameraFrame(camera);
  const double tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5);
  const double aspect = double(width) / double(height);
  gpu_shared::CameraRaysPush push{};
  push.origin = glm::vec4(originInRayFrame, 0.0f);
  push.forward = glm::vec4(glm::vec3(f.forward), 0.0f);
  push.right = glm::vec4(glm::vec3(f.right * (tanHalf * aspect)), 0.0f);
  push.up = glm::vec4(glm::vec3(f.up * tanHalf), 0.0f);
  push.size = glm::uvec4(std::uint32_t(width), std::uint32_t(height), 0u, 0u);
  return push;
}

}  // namespace sdfstream
