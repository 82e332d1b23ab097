// A free-flying camera: position + yaw/pitch, moved by held keys at a speed the wheel scales,
// turned by mouse motion. No roll; pitch stays short of straight up or down so the view's up
// vector is always defined.
#pragma once

#include "gi/camera.h"
#include "viewer/view_input.h"

namespace sdfstream::viewer {

class FlyCamera {
 public:
  // Starts at `start` (position, looking at its target), moving `speed` metres a second.
  FlyCamera(const Camera& start, double speed);

  // Moves by what is held for `seconds` and turns by the mouse motion (0.15 degrees a pixel;
  // moving the mouse right turns right, up looks up); Reset presses go back to the start.
  void update(const FrameInput& input, double seconds);
  // Jumps to `camera` (a scripted waypoint); speed unchanged.
  void set(const Camera& camera);

  Camera camera() const;
  double speed() const { return speed_; }
  double yawDegrees() const { return yaw_; }
  double pitchDegrees() const { return pitch_; }

 private:
  glm::dvec3 forward() const;

  Camera start_;
  double startSpeed_;
  glm::dvec3 position_;
  double yaw_ = 0.0, pitch_ = 0.0;  // degrees; yaw 0 looks along -z, 90 along +x
  double fovY_;
  double speed_;
};

}  // namespace sdfstream::viewer
