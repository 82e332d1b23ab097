#include "viewer/view_script.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/read_file.h"

namespace sdfstream::viewer {
namespace {

class ScriptReader {
 public:
  explicit ScriptReader(const std::string& file) : file_(file) {}

  void line(int lineNumber, std::string_view text) {
    line_ = lineNumber;
    std::istringstream words{std::string(text.substr(0, text.find('#')))};
    std::string command;
    if (!(words >> command)) return;
    if (command == "camera") {
      pending_.camera = camera(word(words, "a camera px,py,pz,tx,ty,tz[,fov]"));
    } else if (command == "hold") {
      const std::string keys = word(words, "keys");
      const int n = count(word(words, "a frame count"));
      for (int i = 0; i < n; ++i) {
        for (std::size_t at = 0; at <= keys.size();) {
          const std::size_t plus = std::min(keys.find('+', at), keys.size());
          pending_.input.held[int(action(keys.substr(at, plus - at)))] = true;
          at = plus + 1;
        }
        emit();
      }
    } else if (command == "press") {
      ++pending_.input.presses[int(action(word(words, "a key")))];
    } else if (command == "look") {
      pending_.input.look.x += number(word(words, "DX"));
      pending_.input.look.y += number(word(words, "DY"));
    } else if (command == "wheel") {
      pending_.input.wheel += number(word(words, "a step count"));
    } else if (command == "frames") {
      const int n = count(word(words, "a frame count"));
      for (int i = 0; i < n; ++i) emit();
    } else if (command == "settle") {
      pending_.settle = true;
    } else if (command == "capture") {
      const std::string name = word(words, "a name");
      if (name.find('/') != std::string::npos || name == "." || name == "..")
        fail("capture " + name + ": expected a plain file name");
      if (frames_.empty()) fail("capture before any frame: nothing has been presented yet");
      frames_.back().captures.push_back(name);
    } else if (command == "quit") {
      done_ = true;
    } else {
      fail("unknown command '" + command +
           "' (expected camera, hold, press, look, wheel, frames, settle, capture or quit)");
    }
    std::string extra;
    if (words >> extra) fail("unexpected '" + extra + "' after " + command);
  }

  bool done() const { return done_; }
  std::vector<ScriptFrame> finish() {
    // Input given after the last frame (a press with no frame to follow) still gets its frame.
    if (pending_.camera || pending_.settle || hasInput(pending_.input)) emit();
    return std::move(frames_);
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(InputErrorKind::Malformed, file_,
                     "line " + std::to_string(line_) + ": " + problem);
  }
  std::string word(std::istringstream& words, const char* what) const {
    std::string w;
    if (!(words >> w)) fail(std::string("expected ") + what);
    return w;
  }
  double number(const std::string& text) const {
    double v = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
      fail("'" + text + "' is not a finite number");
    return v;
  }
  int count(const std::string& text) const {
    int v = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || v < 0 || v > 10'000'000)
      fail("'" + text + "' is not a frame count (0..10000000)");
    return v;
  }
  Action action(std::string_view key) const {
    const auto a = actionOfKey(key);
    if (!a) fail("unknown key '" + std::string(key) + "' (sdfstream view --help lists them)");
    return *a;
  }
  Camera camera(const std::string& text) const {
    const auto c = parseCamera(text);
    if (!c) fail("'" + text + "' is not a camera px,py,pz,tx,ty,tz[,fov]");
    return *c;
  }
  static bool hasInput(const FrameInput& in) {
    for (int a = 0; a < kActionCount; ++a)
      if (in.held[a] || in.presses[a]) return true;
    return in.look != glm::dvec2(0.0) || in.wheel != 0.0;
  }
  void emit() {
    frames_.push_back(std::move(pending_));
    pending_ = ScriptFrame{};
  }

  const std::string& file_;
  int line_ = 0;
  bool done_ = false;
  ScriptFrame pending_;
  std::vector<ScriptFrame> frames_;
};

}  // namespace

std::vector<ScriptFrame> parseViewScript(std::string_view text, const std::string& file) {
  ScriptReader reader(file);
  int number = 0;
  for (std::size_t at = 0; at < text.size() && !reader.done();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    reader.line(++number, text.substr(at, end - at));
    at = end + 1;
  }
  return reader.finish();
}

std::vector<ScriptFrame> readViewScript(const std::filesystem::path& path) {
  const std::string text = readWholeFile<std::string>(path, path.string());
  return parseViewScript(text, path.string());
}

}  // namespace sdfstream::viewer
