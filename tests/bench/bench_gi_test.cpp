// sdfstream bench gi end to end on the smallest run that still writes every output: the built-in
// Cornell box (the data folder is pointed somewhere empty, so the in-code box from Cornell's
// measurements is used, as on a user's machine), one cheap configuration, tiny views and a few
// reference paths. Sponza is asked for too and must be skipped with a message, not fail.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

using Result = test::CliResult;

Result runCli(const std::string& arguments) {
  return test::runCli(SDFSTREAM_CLI, arguments, /*mergeStderr=*/true);
}

TEST(BenchGi, BuiltInCornellBoxWritesCsvSummaryAndPlot) {
  const fs::path dir = test::scratchDir("bench-gi");
  const fs::path empty = dir / "no-data";
  fs::create_directories(empty);
  const Result r = runCli("bench gi --scenes cornell-box,sponza --data " + empty.string() +
                          " --out " + (dir / "out").string() +
                          " --configs spacing-4 --frames 3 --measure 1 --converge-cap 4"
                          " --samples 8 --width 24 --height 18 --no-peers");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("sponza:"), std::string::npos) << r.out;  // skipped, with a message
  EXPECT_EQ(r.out.find("[vulkan"), std::string::npos) << r.out;  // no validation message
  const std::string csv = test::readText(dir / "out" / "results.csv");
  EXPECT_EQ(csv.rfind("scene,config,family,rays,", 0), 0u) << csv;
  EXPECT_NE(csv.find("\ncornell-box,spacing-4,ours,128,4,1,"), std::string::npos) << csv;
  const std::string md = test::readText(dir / "out" / "summary.md");
  EXPECT_NE(md.find("built in code from Cornell's measurements"), std::string::npos) << md;
  EXPECT_NE(md.find("## sponza\n\nSkipped:"), std::string::npos) << md;
  EXPECT_NE(md.find("Pareto front"), std::string::npos) << md;
  EXPECT_TRUE(fs::exists(dir / "out" / "cornell-box" / "error-vs-time.png"));
  EXPECT_TRUE(fs::exists(dir / "out" / "cornell-box" / "front-reference.png"));
  // The reference is cached: a second run loads it instead of tracing again.
  const Result again = runCli("bench gi --scenes cornell-box --data " + empty.string() + " --out " +
                              (dir / "out").string() +
                              " --configs spacing-4 --frames 1 --measure 1 --converge-cap 0"
                              " --samples 8 --width 24 --height 18 --no-peers");
  ASSERT_EQ(again.exitCode, 0) << again.out;
  EXPECT_NE(again.out.find("loaded from cache"), std::string::npos) << again.out;

  const Result bad = runCli("bench gi --scenes atlantis");
  EXPECT_EQ(bad.exitCode, 2) << bad.out;
  EXPECT_NE(bad.out.find("unknown scene 'atlantis'"), std::string::npos) << bad.out;
}

}  // namespace
}  // namespace sdfstream
