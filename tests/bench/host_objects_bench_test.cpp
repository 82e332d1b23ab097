// sdfstream bench host end to end on a small run: every part is timed at each count, the table
// and the exponents reach summary.md, results.csv has a row per count, and bad arguments get
// one line and no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/run_cli.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

test::CliResult runCli(const std::string& arguments) {
  return test::runCli(SDFSTREAM_CLI, arguments);
}

std::vector<std::vector<std::string>> readCsv(const fs::path& file) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

TEST(BenchHost, SmallRunTimesEveryPartAtEveryCount) {
  const fs::path out = fs::temp_directory_path() / ("bench-host-" + std::to_string(::getpid()));
  fs::remove_all(out);
  const test::CliResult r =
      runCli("bench host --objects 20,200 --frames 4 --warmup 2 --threads 1 --out " + out.string());
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("| objects | motion |"), std::string::npos) << r.out;
  std::ifstream md(out / "summary.md");
  const std::string summary((std::istreambuf_iterator<char>(md)), {});
  EXPECT_NE(summary.find("| 200 |"), std::string::npos) << summary;
  EXPECT_NE(summary.find("20 -> 200:"), std::string::npos) << summary;  // the exponent
  const auto rows = readCsv(out / "results.csv");
  ASSERT_EQ(rows.size(), 3u);
  const std::vector<std::string>& header = rows[0];
  auto column = [&](const std::string& name) {
    return std::size_t(std::find(header.begin(), header.end(), name) - header.begin());
  };
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const std::vector<std::string>& row = rows[k];
    ASSERT_EQ(row.size(), header.size());
    EXPECT_EQ(row[column("objects")], k == 1 ? "20" : "200");
    EXPECT_EQ(row[column("frames")], "4");
    EXPECT_EQ(row[column("threads")], "1");
    EXPECT_GT(std::stod(row[column("total_ms")]), 0.0);
    EXPECT_GT(std::stod(row[column("shadow_pages_ms")]), 0.0);
    EXPECT_GT(std::stod(row[column("instances_ms")]), 0.0);
    // Every object moves every frame: each leaves one changed box, and its shadow marks pages.
    EXPECT_EQ(row[column("changed_boxes")], row[column("objects")]);
    EXPECT_GT(std::stod(row[column("pages_marked")]), 0.0);
  }
  fs::remove_all(out);
}

TEST(BenchHost, BadArgumentsGetOneLineAndNoOutput) {
  const fs::path out = fs::temp_directory_path() / ("bench-host-bad-" + std::to_string(::getpid()));
  fs::remove_all(out);
  for (const std::string& bad :
       {"--objects 10,x", "--frames 0", "--meshes 1", "--objects ,", "--threads 0"}) {
    const test::CliResult r = runCli("bench host " + bad + " --out " + out.string());
    EXPECT_NE(r.exitCode, 0) << bad;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << bad;
  }
}

}  // namespace
}  // namespace sdfstream
