// `sdfstream view` as a user meets it: under Xvfb it opens a real window, flies a scripted
// path, and the swapchain image it reads back equals the headless render of the same frames;
// the script's end and Escape close it cleanly with no validation message; without a display it
// says so in one line; a bad script fails before any window opens.
#include <gtest/gtest.h>

#include <stb_image.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

bool haveXvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

// The Cornell box at 5 cm (981 bricks): small enough for a few GI frames on lavapipe.
fs::path cornellWorld(const fs::path& dir) {
  const fs::path input = test::sourceDir() / "tests/gltf/data/cornell-quantized.glb";
  const test::CliResult imp =
      test::runCli(SDFSTREAM_CLI, "import " + input.string() + " -o " + (dir / "world").string() +
                                      " --voxel 0.05");
  EXPECT_EQ(imp.exitCode, 0) << imp.err;
  return dir / "world";
}

fs::path writeScript(const fs::path& dir, const std::string& name, const std::string& text) {
  fs::create_directories(dir);
  std::ofstream(dir / name) << text;
  return dir / name;
}

struct Picture {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

Picture readPng(const fs::path& file) {
  Picture p;
  int channels = 0;
  unsigned char* data = stbi_load(file.c_str(), &p.width, &p.height, &channels, 3);
  if (data) p.rgb.assign(data, data + std::size_t(p.width) * p.height * 3);
  stbi_image_free(data);
  return p;
}

// xvfb-run with its own server number (-a) and a screen larger than the window; validation on.
std::string inXvfb() {
  return "SDFSTREAM_VALIDATION=1 timeout 600 xvfb-run -a -s '-screen 0 640x480x24' " +
         std::string(SDFSTREAM_CLI);
}

// The front of the open box, a flight forward, a turn and a view change, captured on the way.
const char* kScript =
    "camera 0,1,3.2,0,1,0,45\n"
    "settle\n"
    "frames 3\n"
    "capture start\n"
    "hold W 2\n"
    "look 30 -10\n"
    "frames 1\n"
    "capture moved\n"
    "press V\n"
    "press V\n"
    "press V\n"
    "frames 1\n"
    "capture albedo\n";

TEST(ViewCli, WindowCaptureEqualsTheHeadlessRender) {
  if (!haveXvfb()) GTEST_SKIP() << "xvfb-run is not installed (Debian: xvfb)";
  const fs::path dir = test::scratchDir("view-window");
  const fs::path world = cornellWorld(dir);
  const fs::path script = writeScript(dir, "flight.txt", kScript);
  const std::string common = " " + world.string() + " --script " + script.string() +
                             " --width 160 --height 120 --scale 1 --no-hud";
  const test::CliResult window =
      test::runCli(inXvfb(), "view" + common + " -o " + (dir / "window").string());
  ASSERT_EQ(window.exitCode, 0) << window.out << window.err;
  EXPECT_NE(window.out.find("view: 0 validation messages"), std::string::npos) << window.out;
  EXPECT_NE(window.out.find("view: 7 frames shown, "), std::string::npos) << window.out;
  const test::CliResult headless =
      test::runCli(std::string(SDFSTREAM_CLI),
                   "view" + common + " --headless -o " + (dir / "headless").string());
  ASSERT_EQ(headless.exitCode, 0) << headless.err;

  // Stated tolerance: the GI's float sums may round differently from run to run, so a pixel may
  // differ by a level or two; the copy to the swapchain and back must lose nothing more.
  for (const char* name : {"start", "moved", "albedo"}) {
    const Picture a = readPng(dir / "window" / (std::string(name) + ".png"));
    const Picture b = readPng(dir / "headless" / (std::string(name) + ".png"));
    ASSERT_EQ(a.width, 160) << name;
    ASSERT_EQ(a.height, 120) << name;
    ASSERT_EQ(a.rgb.size(), b.rgb.size()) << name;
    double sum = 0.0;
    std::size_t far = 0, lit = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) {
      const int d = std::abs(int(a.rgb[i]) - int(b.rgb[i]));
      sum += d;
      far += d > 2;
      lit += a.rgb[i] > 20;
    }
    const double mean = sum / double(a.rgb.size());
    std::printf("%s: mean |window - headless| %.4f levels, %.4f%% of values differ by > 2\n", name,
                mean, 100.0 * double(far) / double(a.rgb.size()));
    EXPECT_LE(mean, 0.5) << name;
    EXPECT_LE(double(far) / double(a.rgb.size()), 0.005) << name;
    EXPECT_GT(double(lit) / double(a.rgb.size()), 0.3) << name << ": the box is not in view";
  }
  // The frames moved: flying forward and turning changes the picture.
  EXPECT_NE(readPng(dir / "window" / "start.png").rgb, readPng(dir / "window" / "moved.png").rgb);
  // Three V presses: final -> direct -> indirect -> albedo, a flat-coloured picture.
  EXPECT_NE(readPng(dir / "window" / "moved.png").rgb, readPng(dir / "window" / "albedo.png").rgb);
}

TEST(ViewCli, EscapeClosesTheWindowCleanly) {
  if (!haveXvfb()) GTEST_SKIP() << "xvfb-run is not installed (Debian: xvfb)";
  const fs::path dir = test::scratchDir("view-escape");
  const fs::path world = cornellWorld(dir);
  const fs::path script = writeScript(dir, "escape.txt", "frames 2\npress ESCAPE\nframes 50\n");
  const test::CliResult r =
      test::runCli(inXvfb(), "view " + world.string() + " --script " + script.string() +
                                 " --width 96 --height 64 -o " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("view: 2 frames shown, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("view: 0 validation messages"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("error"), std::string::npos) << r.err;
}

TEST(ViewCli, NoDisplayIsOneLine) {
  const fs::path dir = test::scratchDir("view-no-display");
  const fs::path world = cornellWorld(dir);
  const test::CliResult r = test::runCli(
      "env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(SDFSTREAM_CLI), "view " + world.string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_EQ(r.err.rfind("sdfstream view: error: no display", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

TEST(ViewCli, BadScriptFailsBeforeAWindowOpens) {
  const fs::path dir = test::scratchDir("view-bad-script");
  const fs::path world = cornellWorld(dir);
  const fs::path script = writeScript(dir, "bad.txt", "frames 2\nfly away\n");
  // No display on purpose: the script is read first, so its error, not the display's, shows.
  const test::CliResult r =
      test::runCli("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(SDFSTREAM_CLI),
                   "view " + world.string() + " --script " + script.string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("bad.txt: line 2: unknown command 'fly'"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

}  // namespace
}  // namespace sdfstream
