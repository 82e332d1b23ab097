// `sdfstream fly --objects` end to end on a tiny pack (a 40 x 40 m floor with a tower, 0.5 m
// voxels): the objects are placed on the pack's ground along the path, move, show in the frames
// and are reported in gi.csv and summary.md; `--objects 0` reports none, `--cpu --objects N` is a
// usage error. A few 64 x 48 frames with a small probe budget: seconds on lavapipe.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

using RunResult = test::CliResult;

RunResult run(const std::string& arguments) {
  return test::runCli(SDFSTREAM_CLI, arguments, /*mergeStderr=*/true);
}

// gi.csv as a header -> column map and rows of numbers.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  double at(std::size_t row, const std::string& column) const {
    for (std::size_t c = 0; c < header.size(); ++c)
      if (header[c] == column) return rows.at(row).at(c);
    ADD_FAILURE() << "gi.csv has no column " << column;
    return 0.0;
  }
};
Csv readCsv(const fs::path& file) {
  Csv csv;
  std::istringstream in(test::readText(file));
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    std::istringstream cells(line);
    std::string cell;
    std::vector<double> row;
    while (std::getline(cells, cell, ',')) {
      if (first)
        csv.header.push_back(cell);
      else
        row.push_back(std::stod(cell));
    }
    if (!first) csv.rows.push_back(row);
    first = false;
  }
  return csv;
}

TEST(FlyObjects, ObjectsShowInFramesAndMetrics) {
  const fs::path dir = test::scratchDir("fly-objects");
  std::ofstream(dir / "layout.json") << R"({"boxes": [
    {"min": [-20.0, -1.0, -20.0], "max": [20.0, 0.0, 20.0], "albedo": [0.5, 0.6, 0.4]},
    {"min": [16.0, 0.0, 16.0], "max": [18.0, 12.0, 18.0], "albedo": [0.7, 0.7, 0.7]}]})";
  const RunResult imp = run("import " + (dir / "layout.json").string() + " -o " +
                            (dir / "pack").string() + " --voxel 0.5 --lods 2 --tile-voxels 64");
  ASSERT_EQ(imp.exitCode, 0) << imp.out;

  const std::string common = "fly " + (dir / "pack").string() +
                             " --frames 4 --image-every 3 --speed 5 --width 64 --height 48 "
                             "--cascades 2 --probe-rays 16 --probe-budget 2048 --gi-frames 2 ";
  const RunResult with = run(common + "-o " + (dir / "with").string() + " --objects 40");
  ASSERT_EQ(with.exitCode, 0) << with.out;
  EXPECT_EQ(with.out.find("[vulkan"), std::string::npos) << with.out;
  EXPECT_TRUE(fs::exists(dir / "with/frames/frame-0000.png"));
  EXPECT_TRUE(fs::exists(dir / "with/frames/frame-0003.png"));
  const Csv csv = readCsv(dir / "with/gi.csv");
  ASSERT_EQ(csv.rows.size(), 4u);
  const double instances = csv.at(0, "object_instances");
  std::printf("%g objects placed; frame 0: %g pixels on objects, %g probe rays searched them\n",
              instances, csv.at(0, "object_pixels"), csv.at(0, "object_rays"));
  // Placed only where the pack has ground: up to 25 m off a path inside a 40 m floor, so some
  // fall outside it and are skipped.
  EXPECT_GE(instances, 15.0);
  EXPECT_LE(instances, 40.0);
  EXPECT_GT(csv.at(0, "object_pixels"), 20.0) << "the objects ahead should show in frame 0";
  EXPECT_GT(csv.at(3, "object_pixels"), 20.0);
  EXPECT_GT(csv.at(1, "object_rays"), 0.0) << "the probes should trace the objects";
  EXPECT_GT(csv.at(1, "object_region_ms"), 0.0);
  const std::string summary = test::readText(dir / "with/summary.md");
  EXPECT_NE(summary.find("## Moving objects"), std::string::npos) << summary;

  const RunResult none = run(common + "-o " + (dir / "none").string() + " --objects 0");
  ASSERT_EQ(none.exitCode, 0) << none.out;
  const Csv csvNone = readCsv(dir / "none/gi.csv");
  EXPECT_EQ(csvNone.at(0, "object_instances"), 0.0);
  EXPECT_EQ(csvNone.at(0, "object_pixels"), 0.0);
  EXPECT_EQ(test::readText(dir / "none/summary.md").find("## Moving objects"), std::string::npos);
  // The objects change the picture.
  EXPECT_NE(test::readText(dir / "with/frames/frame-0000.png"),
            test::readText(dir / "none/frames/frame-0000.png"));

  const RunResult cpu = run(common + "-o " + (dir / "cpu").string() + " --cpu --objects 5");
  EXPECT_EQ(cpu.exitCode, 2) << cpu.out;
  EXPECT_FALSE(fs::exists(dir / "cpu/gi.csv"));
}

}  // namespace
}  // namespace sdfstream
