#include "viewer/view_input.h"

#include <algorithm>
#include <cctype>

namespace sdfstream::viewer {
namespace {

struct Binding {
  Action action;
  std::string_view key;
  std::string_view help;
};

constexpr Binding kBindings[] = {
    {Action::Forward, "W", "move forward"},
    {Action::Back, "S", "move back"},
    {Action::Left, "A", "move left"},
    {Action::Right, "D", "move right"},
    {Action::Up, "E", "move up"},
    {Action::Down, "Q", "move down"},
    {Action::Fast, "LSHIFT", "move 4x faster while held (wheel: speed x1.25 a step)"},
    {Action::Pause, "P", "pause the objects and the sun (streaming and GI go on)"},
    {Action::Reset, "R", "camera back to its start"},
    {Action::Screenshot, "F12", "write the next frame to OUT/screenshot-NNNN.png"},
    {Action::ToggleGi, "G", "indirect light on/off (off pauses the probe updates too)"},
    {Action::NextView, "V",
     "view: final, direct, indirect, albedo, normals, cascade, residency, probe states, "
     "object regions"},
    {Action::ToggleHud, "H", "HUD on/off"},
    {Action::SunLeft, "LEFT", "sun azimuth -5 degrees"},
    {Action::SunRight, "RIGHT", "sun azimuth +5 degrees"},
    {Action::SunUp, "UP", "sun elevation +5 degrees"},
    {Action::SunDown, "DOWN", "sun elevation -5 degrees"},
    {Action::SunBrighter, "EQUAL", "sun irradiance x1.25 (the = / + key)"},
    {Action::SunDimmer, "MINUS", "sun irradiance /1.25"},
    {Action::Quit, "ESCAPE", "quit"},
};
static_assert(std::size(kBindings) == kActionCount);

const Binding& binding(Action action) { return kBindings[int(action)]; }

bool sameKey(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::toupper(static_cast<unsigned char>(x)) ==
                  std::toupper(static_cast<unsigned char>(y));
         });
}

}  // namespace

std::string_view keyName(Action action) { return binding(action).key; }
std::string_view actionHelp(Action action) { return binding(action).help; }

std::optional<Action> actionOfKey(std::string_view name) {
  for (const Binding& b : kBindings)
    if (sameKey(b.key, name)) return b.action;
  return std::nullopt;
}

std::string keyHelp() {
  std::string text;
  for (const Binding& b : kBindings) {
    std::string key(b.key);
    key.resize(std::max<std::size_t>(key.size(), 8), ' ');
    text += "  " + key + " " + std::string(b.help) + "\n";
  }
  return text + "  mouse   look around while the right button is held\n";
}

}  // namespace sdfstream::viewer
