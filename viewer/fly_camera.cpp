#include "viewer/fly_camera.h"

#include <algorithm>
#include <cmath>

namespace sdfstream::viewer {
namespace {

constexpr double kDegrees = 3.14159265358979323846 / 180.0;
constexpr double kLookDegreesPerPixel = 0.15;
constexpr double kMaxPitch = 89.0;
constexpr double kFastFactor = 4.0;
constexpr double kWheelFactor = 1.25;

}  // namespace

FlyCamera::FlyCamera(const Camera& start, double speed)
    : start_(start), startSpeed_(speed), speed_(speed) {
  set(start);
}

void FlyCamera::set(const Camera& camera) {
  position_ = camera.position;
  fovY_ = camera.fovYDegrees;
  glm::dvec3 d = camera.target - camera.position;
  if (glm::dot(d, d) == 0.0) d = glm::dvec3(0.0, 0.0, -1.0);
  d = glm::normalize(d);
  pitch_ = std::clamp(std::asin(std::clamp(d.y, -1.0, 1.0)) / kDegrees, -kMaxPitch, kMaxPitch);
  yaw_ = std::atan2(d.x, -d.z) / kDegrees;
}

glm::dvec3 FlyCamera::forward() const {
  const double y = yaw_ * kDegrees, p = pitch_ * kDegrees;
  return {std::sin(y) * std::cos(p), std::sin(p), -std::cos(y) * std::cos(p)};
}

void FlyCamera::update(const FrameInput& input, double seconds) {
  if (input.presses[int(Action::Reset)] > 0) {
    set(start_);
    speed_ = startSpeed_;
  }
  speed_ *= std::pow(kWheelFactor, input.wheel);
  yaw_ += input.look.x * kLookDegreesPerPixel;
  yaw_ = std::remainder(yaw_, 360.0);
  pitch_ = std::clamp(pitch_ - input.look.y * kLookDegreesPerPixel, -kMaxPitch, kMaxPitch);

  const glm::dvec3 f = forward();
  const glm::dvec3 right = glm::normalize(glm::cross(f, glm::dvec3(0.0, 1.0, 0.0)));
  glm::dvec3 move(0.0);
  auto held = [&](Action a) { return input.held[int(a)] ? 1.0 : 0.0; };
  move += f * (held(Action::Forward) - held(Action::Back));
  move += right * (held(Action::Right) - held(Action::Left));
  move += glm::dvec3(0.0, 1.0, 0.0) * (held(Action::Up) - held(Action::Down));
  if (glm::dot(move, move) > 0.0) {
    const double speed = speed_ * (input.held[int(Action::Fast)] ? kFastFactor : 1.0);
    position_ += glm::normalize(move) * speed * seconds;
  }
}

Camera FlyCamera::camera() const {
  Camera c;
  c.position = position_;
  c.target = position_ + forward();
  c.fovYDegrees = fovY_;
  return c;
}

}  // namespace sdfstream::viewer
