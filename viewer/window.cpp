#include "viewer/window.h"

#include <cstdlib>
#include <stdexcept>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

namespace sdfstream::viewer {
namespace {

std::string lastGlfwError;

void onGlfwError(int, const char* description) { lastGlfwError = description ? description : ""; }

// GLFW key code of each action (view_input.h names them).
int glfwKeyOf(Action action) {
  switch (action) {
    case Action::Forward:
      return GLFW_KEY_W;
    case Action::Back:
      return GLFW_KEY_S;
    case Action::Left:
      return GLFW_KEY_A;
    case Action::Right:
      return GLFW_KEY_D;
    case Action::Up:
      return GLFW_KEY_E;
    case Action::Down:
      return GLFW_KEY_Q;
    case Action::Fast:
      return GLFW_KEY_LEFT_SHIFT;
    case Action::Pause:
      return GLFW_KEY_P;
    case Action::Reset:
      return GLFW_KEY_R;
    case Action::Screenshot:
      return GLFW_KEY_F12;
    case Action::ToggleGi:
      return GLFW_KEY_G;
    case Action::NextView:
      return GLFW_KEY_V;
    case Action::ToggleHud:
      return GLFW_KEY_H;
    case Action::SunLeft:
      return GLFW_KEY_LEFT;
    case Action::SunRight:
      return GLFW_KEY_RIGHT;
    case Action::SunUp:
      return GLFW_KEY_UP;
    case Action::SunDown:
      return GLFW_KEY_DOWN;
    case Action::SunBrighter:
      return GLFW_KEY_EQUAL;
    case Action::SunDimmer:
      return GLFW_KEY_MINUS;
    case Action::Quit:
      return GLFW_KEY_ESCAPE;
    case Action::Count:
      break;
  }
  return GLFW_KEY_UNKNOWN;
}

}  // namespace

Window::Window(int width, int height, const std::string& title) {
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit()) {
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((!display || !*display) && (!wayland || !*wayland))
      throw std::runtime_error(
          "no display: DISPLAY is not set (run under a desktop session, or `xvfb-run -a "
          "sdfstream view ...`; `--headless` renders without a window)");
    throw std::runtime_error("cannot open a window: " + lastGlfwError);
  }
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    throw std::runtime_error("cannot open a window: GLFW found no Vulkan loader (" + lastGlfwError +
                             ")");
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    glfwTerminate();
    throw std::runtime_error("cannot open a window: " + lastGlfwError);
  }
  glfwSetWindowUserPointer(window_, this);
  glfwSetKeyCallback(window_, onKey);
  glfwSetScrollCallback(window_, onScroll);
}

Window::~Window() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

bool Window::closeRequested() const { return glfwWindowShouldClose(window_); }

void Window::onKey(GLFWwindow* handle, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  auto* self = static_cast<Window*>(glfwGetWindowUserPointer(handle));
  for (int a = 0; a < kActionCount; ++a)
    if (glfwKeyOf(Action(a)) == key) ++self->pending_.presses[a];
}

void Window::onScroll(GLFWwindow* handle, double, double dy) {
  static_cast<Window*>(glfwGetWindowUserPointer(handle))->pending_.wheel += dy;
}

FrameInput Window::poll() {
  glfwPollEvents();
  FrameInput input = pending_;
  pending_ = FrameInput{};
  for (int a = 0; a < kActionCount; ++a)
    if (isHeld(Action(a))) input.held[a] = glfwGetKey(window_, glfwKeyOf(Action(a))) == GLFW_PRESS;
  const bool right = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
  glm::dvec2 cursor;
  glfwGetCursorPos(window_, &cursor.x, &cursor.y);
  if (right && looking_) input.look = cursor - lastCursor_;
  looking_ = right;
  lastCursor_ = cursor;
  if (input.presses[int(Action::Quit)] > 0) glfwSetWindowShouldClose(window_, GLFW_TRUE);
  return input;
}

glm::ivec2 Window::framebufferSize() const {
  glm::ivec2 size;
  glfwGetFramebufferSize(window_, &size.x, &size.y);
  return size;
}

void Window::setTitle(const std::string& title) { glfwSetWindowTitle(window_, title.c_str()); }

}  // namespace sdfstream::viewer
