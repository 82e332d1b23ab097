// The fly camera: keys move it along its own axes at its speed, the mouse turns it, the wheel
// scales the speed, Reset goes back, and the pitch never reaches the poles.
#include <gtest/gtest.h>

#include "viewer/fly_camera.h"

namespace sdfstream::viewer {
namespace {

Camera lookingAlongMinusZ() {
  Camera c;
  c.position = glm::dvec3(1, 2, 3);
  c.target = glm::dvec3(1, 2, 0);
  return c;
}

void expectNear(glm::dvec3 a, glm::dvec3 b) {
  EXPECT_NEAR(a.x, b.x, 1e-9);
  EXPECT_NEAR(a.y, b.y, 1e-9);
  EXPECT_NEAR(a.z, b.z, 1e-9);
}

TEST(FlyCamera, HeldKeysMoveAlongTheViewAtTheSpeed) {
  FlyCamera cam(lookingAlongMinusZ(), 2.0);
  FrameInput in;
  in.held[int(Action::Forward)] = true;
  cam.update(in, 0.5);
  expectNear(cam.camera().position, {1, 2, 2});  // 2 m/s for 0.5 s along -z
  in = FrameInput{};
  in.held[int(Action::Right)] = true;
  in.held[int(Action::Fast)] = true;
  cam.update(in, 0.25);
  expectNear(cam.camera().position, {3, 2, 2});  // 4x: 8 m/s for 0.25 s along +x
  in = FrameInput{};
  in.held[int(Action::Up)] = true;
  in.held[int(Action::Down)] = true;  // opposite keys cancel
  cam.update(in, 1.0);
  expectNear(cam.camera().position, {3, 2, 2});
}

TEST(FlyCamera, MouseTurnsWheelScalesResetReturns) {
  FlyCamera cam(lookingAlongMinusZ(), 2.0);
  FrameInput in;
  in.look = glm::dvec2(600.0, 0.0);  // 0.15 degrees a pixel: 90 degrees to the right
  in.wheel = 2.0;
  cam.update(in, 0.0);
  const Camera c = cam.camera();
  expectNear(glm::normalize(c.target - c.position), {1, 0, 0});
  EXPECT_NEAR(cam.speed(), 2.0 * 1.25 * 1.25, 1e-12);
  in = FrameInput{};
  in.look = glm::dvec2(0.0, -10000.0);  // far past straight up
  cam.update(in, 0.0);
  EXPECT_LE(cam.pitchDegrees(), 89.0);
  EXPECT_GT(cam.pitchDegrees(), 88.0);
  in = FrameInput{};
  in.presses[int(Action::Reset)] = 1;
  cam.update(in, 0.0);
  expectNear(cam.camera().position, {1, 2, 3});
  EXPECT_NEAR(cam.pitchDegrees(), 0.0, 1e-9);
  EXPECT_NEAR(cam.yawDegrees(), 0.0, 1e-9);
  EXPECT_EQ(cam.speed(), 2.0);
}

TEST(FlyCamera, SetKeepsTheDirectionOfAWaypoint) {
  FlyCamera cam(lookingAlongMinusZ(), 1.0);
  Camera w;
  w.position = glm::dvec3(0, 0, 0);
  w.target = glm::dvec3(1, 1, 0);
  w.fovYDegrees = 40.0;
  cam.set(w);
  const Camera c = cam.camera();
  expectNear(glm::normalize(c.target - c.position), glm::normalize(glm::dvec3(1, 1, 0)));
  EXPECT_EQ(c.fovYDegrees, 40.0);
}

}  // namespace
}  // namespace sdfstream::viewer
