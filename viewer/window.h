// The viewer's GLFW window (no client API: Vulkan presents into it) and its input, turned into
// the viewer's actions (view_input.h). One per process; the GLFW library is initialised by the
// first Window and terminated with it.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "viewer/view_input.h"

struct GLFWwindow;

namespace sdfstream::viewer {

class Window {
 public:
  // Throws std::runtime_error with one line when there is no display to open a window on
  // ("no display: DISPLAY is not set ..."), or when GLFW finds no Vulkan loader.
  Window(int width, int height, const std::string& title);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  GLFWwindow* handle() const { return window_; }
  bool closeRequested() const;
  // Polls events and returns this frame's input: keys held now, presses since the last poll,
  // mouse motion while the right button is held, scroll steps.
  FrameInput poll();
  // The drawable size in pixels (0 x 0 while minimised).
  glm::ivec2 framebufferSize() const;
  void setTitle(const std::string& title);

 private:
  static void onKey(GLFWwindow* window, int key, int scancode, int action, int mods);
  static void onScroll(GLFWwindow* window, double dx, double dy);

  GLFWwindow* window_ = nullptr;
  FrameInput pending_;  // presses and scroll since the last poll
  glm::dvec2 lastCursor_{0.0};
  bool looking_ = false;
};

}  // namespace sdfstream::viewer
