// What the viewer's keys do, named once: the window's key callback, the --script reader and the
// help text all go through this table, so a scripted run presses the same keys a person would.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

namespace sdfstream::viewer {

enum class Action : std::uint8_t {
  // Held: the camera moves while the key is down.
  Forward,
  Back,
  Left,
  Right,
  Up,
  Down,
  Fast,
  // Pressed: once per press.
  Pause,       // objects and the sun stop (streaming and GI go on)
  Reset,       // the camera back to where it started
  Screenshot,  // the next presented frame to OUT/screenshot-NNNN.png
  ToggleGi,    // probe updates and indirect light on/off
  NextView,    // final, direct, indirect, albedo, normals, cascade, residency, probe states,
               // object regions
  ToggleHud,
  SunLeft,
  SunRight,
  SunUp,
  SunDown,  // the sun's azimuth / elevation, 5 degrees a press
  SunBrighter,
  SunDimmer,  // the sun's irradiance, x1.25 a press
  Quit,
  Count
};
constexpr int kActionCount = int(Action::Count);

constexpr bool isHeld(Action a) { return a <= Action::Fast; }

// The key bound to an action, as the script and the help spell it ("W", "LSHIFT", "F12").
std::string_view keyName(Action action);
// The action of a key name (case-insensitive), or none.
std::optional<Action> actionOfKey(std::string_view name);
// What the action does, for --help and the HUD's key list.
std::string_view actionHelp(Action action);
// "  W  forward\n  S  back\n..." for --help.
std::string keyHelp();

// One frame's input, from the window or from the script.
struct FrameInput {
  bool held[kActionCount] = {};    // held this frame
  int presses[kActionCount] = {};  // pressed this frame
  glm::dvec2 look{0.0};            // mouse motion, pixels (right button held, or scripted)
  double wheel = 0.0;              // scroll steps: camera speed ×1.25 each
};

}  // namespace sdfstream::viewer
