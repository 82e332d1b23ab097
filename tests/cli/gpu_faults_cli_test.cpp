// GPU faults as the command-line user meets them: a lost device (injected) ends render and fly
// with one line and a non-zero exit, never a hang, and writes no image; a memory budget the
// device cannot hold is refused at start-up naming the budget and the device's memory.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

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
    test::CliResult render = test::runCli(
        lostAfter(submits), "render " + world + " -o " + (dir / "lost.png").string() +
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
  test::CliResult r =
      test::runCli(SDFSTREAM_CLI, "fly " + (dir / "world").string() + " -o " +
                                      (dir / "fly").string() + " --frames 2 --atlas-mib 1000000");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("[too-large]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1000000 MiB"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("device-local memory"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "fly"));
  test::CliResult silly =
      test::runCli(SDFSTREAM_CLI, "fly " + (dir / "world").string() + " -o " +
                                      (dir / "fly").string() + " --frames 2 --atlas-mib -5");
  EXPECT_EQ(silly.exitCode, 2) << silly.err;
  EXPECT_EQ(lineCount(silly.err), 1) << silly.err;
}

// The live GPU buffers (MiB) of fly's progress lines, in order.
std::vector<double> liveGpuMiB(const std::string& err) {
  std::vector<double> mib;
  for (std::size_t at = err.find("GPU buffers "); at != std::string::npos;
       at = err.find("GPU buffers ", at + 1))
    mib.push_back(std::stod(err.substr(at + 12)));
  return mib;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The sum of fly's metrics.csv column atlas_full_pages: pages that had no atlas slot.
std::uint64_t atlasFullPages(const fs::path& metricsCsv) {
  std::istringstream rows(readText(metricsCsv));
  std::string header, row;
  std::getline(rows, header);
  int column = 0;
  for (std::size_t at = 0; at < header.find("atlas_full_pages"); ++at) column += header[at] == ',';
  std::uint64_t sum = 0;
  while (std::getline(rows, row)) {
    std::istringstream cells(row);
    std::string cell;
    for (int c = 0; c <= column; ++c) std::getline(cells, cell, ',');
    sum += std::stoull(cell);
  }
  return sum;
}

// fly on `world` into `out`, with the device pretending to hold at most `limitMiB` MiB of
// device-local buffers when limitMiB >= 0 (SDFSTREAM_INJECT_DEVICE_MEMORY_MIB).
test::CliResult fly(const std::string& world, const fs::path& out, const std::string& args,
                    int limitMiB = -1) {
  const std::string env =
      limitMiB < 0
          ? std::string()
          : "SDFSTREAM_INJECT_DEVICE_MEMORY_MIB=" + std::to_string(limitMiB) + " timeout 300 ";
  return test::runCli(env + SDFSTREAM_CLI, "fly " + world + " -o " + out.string() + args);
}

// The device pretends to have less memory than the GI and the atlas need together
// (SDFSTREAM_INJECT_DEVICE_MEMORY_MIB): fly keeps fewer atlas slots, says so, finishes, and the
// summary reports it, instead of dying on the allocation.
TEST(CliGpuFaults, TooLittleDeviceMemoryForTheAtlasDegradesAndIsCounted) {
  const fs::path dir = smallWorld("cli-device-oom");
  const std::string world = (dir / "world").string();
  const std::string args =
      " --frames 4 --width 32 --height 24 --no-pacing --objects 0 "
      "--atlas-mib 32 --probe-budget 4096";
  // What the run needs with the whole atlas: the peak of the progress lines' live GPU buffers
  // (passes that keep device-local copies of their inputs allocate them on first use, after the
  // atlas is reserved, so the first line can be below the peak).
  const test::CliResult full = fly(world, dir / "full", args);
  ASSERT_EQ(full.exitCode, 0) << full.err;
  const std::vector<double> live = liveGpuMiB(full.err);
  ASSERT_FALSE(live.empty()) << full.err;
  const double needed = *std::max_element(live.begin(), live.end());
  // 20 MiB short: the 32 MiB atlas does not fit, a quarter of it does.
  const test::CliResult lean = fly(world, dir / "lean", args, int(needed) - 20);
  EXPECT_EQ(lean.exitCode, 0) << lean.err;
  EXPECT_NE(lean.err.find("note: the device's memory holds"), std::string::npos) << lean.err;
  EXPECT_EQ(lean.err.find("error"), std::string::npos) << lean.err;
  const std::string text = readText(dir / "lean" / "summary.md");
  EXPECT_NE(text.find("Device memory held"), std::string::npos) << text;
}

// The device runs out of memory after the first frames (SDFSTREAM_INJECT_DEVICE_OOM_FRAME: a
// frame's GPU part fails as an allocation would): the brick atlas gives back half its slots, the
// frame runs again, the run finishes with fewer resident bricks, counted as atlas-full pages,
// instead of an error. The failure is injected at a frame, not at a byte limit, because which
// frame's passes grow depends on how fast the loader streams.
TEST(CliGpuFaults, RunningOutOfDeviceMemoryMidRunShrinksTheAtlasAndFinishes) {
  const fs::path dir = smallWorld("cli-device-oom-mid-run");
  const std::string world = (dir / "world").string();
  // A 3 MiB atlas holds the 380 bricks this flight needs (2 MiB hold 377), half of it does not:
  // after the shrink some pages must count as atlas-full.
  const std::string args =
      " --frames 6 --width 32 --height 24 --no-pacing --objects 0 "
      "--atlas-mib 3 --probe-budget 4096";
  const test::CliResult full = fly(world, dir / "full", args);
  ASSERT_EQ(full.exitCode, 0) << full.err;
  ASSERT_EQ(atlasFullPages(dir / "full" / "metrics.csv"), 0u) << full.err;
  EXPECT_EQ(full.err.find("ran out of device memory"), std::string::npos) << full.err;
  const test::CliResult lean =
      test::runCli(std::string("SDFSTREAM_INJECT_DEVICE_OOM_FRAME=2 timeout 300 ") + SDFSTREAM_CLI,
                   "fly " + world + " -o " + (dir / "lean").string() + args);
  EXPECT_EQ(lean.exitCode, 0) << lean.err;
  EXPECT_EQ(lean.err.find("note: the device's memory holds"), std::string::npos) << lean.err;
  EXPECT_NE(lean.err.find("note: frame 2 ran out of device memory"), std::string::npos) << lean.err;
  EXPECT_EQ(lean.err.find("error"), std::string::npos) << lean.err;
  EXPECT_NE(readText(dir / "lean" / "summary.md").find("mid-run when the device ran out of memory"),
            std::string::npos);
  // The bricks that no longer fit are counted, not lost silently.
  EXPECT_GT(atlasFullPages(dir / "lean" / "metrics.csv"), 0u) << lean.err;
}

}  // namespace
}  // namespace sdfstream
