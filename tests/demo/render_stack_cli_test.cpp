// `sdfstream render` streams the whole cascade stack: a world larger than one cascade is framed
// whole by the default camera, where a single cascade shows a fragment of it.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {

// "N/M rays hit" of render's summary line, as the fraction N/M (-1 when absent).
double hitFraction(const std::string& out) {
  std::smatch m;
  if (!std::regex_search(out, m, std::regex("([0-9]+)/([0-9]+) rays hit"))) return -1.0;
  return std::stod(m[1]) / std::stod(m[2]);
}

TEST(RenderStackCli, AWorldLargerThanOneCascadeIsFramedWhole) {
  const auto dir = test::scratchDir("render-stack");
  // The 2 m Cornell box at 1 cm: one 128^3 cascade of LOD 0 spans 1.28 m of it.
  const auto input = test::sourceDir() / "tests/gltf/data/cornell-quantized.glb";
  const auto world = (dir / "world").string();
  const test::CliResult imp =
      test::runCli(SDFSTREAM_CLI, "import " + input.string() + " -o " + world + " --voxel 0.01");
  ASSERT_EQ(imp.exitCode, 0) << imp.err;
  const std::string common = " --width 96 --height 54 --gi off";
  const test::CliResult stack = test::runCli(
      SDFSTREAM_CLI, "render " + world + " -o " + (dir / "stack.png").string() + common);
  ASSERT_EQ(stack.exitCode, 0) << stack.err;
  const test::CliResult one =
      test::runCli(SDFSTREAM_CLI, "render " + world + " -o " + (dir / "one.png").string() + common +
                                      " --cascades 1");
  ASSERT_EQ(one.exitCode, 0) << one.err;
  const double all = hitFraction(stack.out), single = hitFraction(one.out);
  EXPECT_GE(all, 0.35) << stack.out;
  EXPECT_GE(all, 5.0 * single) << stack.out << one.out;
}

}  // namespace
}  // namespace sdfstream
