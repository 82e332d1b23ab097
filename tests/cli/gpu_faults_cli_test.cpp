// GPU faults as the command-line user meets them: a lost device (injected) ends render and fly
// with one line and a non-zero exit, never a hang, and writes no image; a memory budget the
// device cannot hold is refused at start-up naming the budget and the device's memory.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// stderr of a command that also reports progress there: exactly one line is the error, and it
// is the last one.
void expectOneErrorLineLast(const std::string& err, const std::string& what) {
  int errors = 0;
  std::size_t start = 0, last = 0;
  while (start < err.size()) {
    const std::size_t end = err.find('\n', start);
    const std::string line = err.substr(start, end - start);
    if (line.find("error") != std::string::npos) ++errors, last = start;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  EXPECT_EQ(errors, 1) << err;
  EXPECT_NE(err.find(what, last), std::string::npos) << err;
  EXPECT_EQ(err.find('\n', last), err.size() - 1) << "the error is not the last line: " << err;
}

fs::path smallWorld(const std::string& name) {
  const fs::path dir = test::scratchDir(name);
  const fs::path input = test::sourceDir() / "tests/gltf/data/cornell-quantized.glb";
  test::CliResult imp = test::runCli(SDFSTREAM_CLI, "import " + input.string() + " -o " +
                                                        (dir / "world").string() + " --voxel 0.05");
  EXPECT_EQ(imp.exitCode, 0) << imp.err;
  return dir;
}

// `timeout` turns a hang into exit code 124, which the expectations below then reject.
std::string lostAfter(int submits) {
  return "SDFSTREAM_INJECT_DEVICE_LOST=" + std::to_string(submits) + " timeout 300 " +
         SDFSTREAM_CLI;
}

TEST(CliGpuFaults, DeviceLostEndsRenderAndFlyWithOneLine) {
  const fs::path dir = smallWorld("cli-device-lost");
  const std::string world = (dir / "world").string();
  for (int submits : {1, 5}) {  // lost at the first GI submit, or a few frames in
    test::CliResult render =
        test::runCli(lostAfter(submits), "render " + world + " -o " + (dir / "lost.png").string() +
                                             " --width 32 --height 24 --gi-frames 8 --probe-rays 16");
    EXPECT_EQ(render.exitCode, 1) << submits << ": " << render.err;
    EXPECT_EQ(lineCount(render.err), 1) << render.err;
    EXPECT_NE(render.err.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << render.err;
    EXPECT_FALSE(fs::exists(dir / "lost.png")) << "no image from a lost device";
  }
  test::CliResult fly = test::runCli(
      lostAfter(20), "fly " + world + " -o " + (dir / "fly").string() +
                         " --frames 40 --width 32 --height 24 --objects 4 --no-pacing");
  EXPECT_EQ(fly.exitCode, 1) << fly.err;
  expectOneErrorLineLast(fly.err, "VK_ERROR_DEVICE_LOST");
}

TEST(CliGpuFaults, AtlasBudgetBeyondTheDeviceIsRefusedAtStartUp) {
  const fs::path dir = smallWorld("cli-budget");
  test::CliResult r = test::runCli(SDFSTREAM_CLI, "fly " + (dir / "world").string() + " -o " +
                                                      (dir / "fly").string() +
                                                      " --frames 2 --atlas-mib 1000000");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("[too-large]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1000000 MiB"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("device-local memory"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "fly"));
  test::CliResult silly = test::runCli(SDFSTREAM_CLI, "fly " + (dir / "world").string() + " -o " +
                                                          (dir / "fly").string() +
                                                          " --frames 2 --atlas-mib -5");
  EXPECT_EQ(silly.exitCode, 2) << silly.err;
  EXPECT_EQ(lineCount(silly.err), 1) << silly.err;
}

}  // namespace
}  // namespace sdfstream
