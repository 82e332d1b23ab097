// The command-line tool as a user meets it: bad input gets exactly one line on stderr naming the
// file and the error class, a non-zero exit code, and no output directory; good input works.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

using RunResult = test::CliResult;

RunResult run(const std::string& arguments) { return test::runCli(SDFSTREAM_CLI, arguments); }

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

void expectCleanFailure(const fs::path& input, const std::string& kind) {
  fs::path out = test::scratchDir("cli-bad") / "world";
  RunResult r = run("import '" + input.string() + "' -o '" + out.string() + "'");
  EXPECT_NE(r.exitCode, 0) << input;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("[" + kind + "]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(input.filename().string()), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "a failed import must leave no output";
  for (const auto& entry : fs::directory_iterator(out.parent_path()))
    ADD_FAILURE() << "left behind: " << entry.path();
}

const fs::path kGltf2 = "/usr/share/assimp/models/glTF2";

// Every file of a world pack (manifest.json and tiles/*.tile) in name order, names and bytes.
std::string packBytes(const fs::path& world) {
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(world))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  std::string all;
  for (const fs::path& f : files) {
    std::ifstream in(f, std::ios::binary);
    all += fs::relative(f, world).string() + "\n";
    all.append(std::istreambuf_iterator<char>(in), {});
  }
  return all;
}

TEST(Cli, BadGltfInputsFailWithOneLineAndNoOutput) {
  expectCleanFailure(kGltf2 / "MissingBin/BoxTextured.gltf", "missing-data");
  expectCleanFailure(kGltf2 / "IndexOutOfRange/IndexOutOfRange.gltf", "out-of-range");
  expectCleanFailure(kGltf2 / "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "non-finite");
  expectCleanFailure(kGltf2 / "wrongTypes/badArray.gltf", "malformed");
  expectCleanFailure(kGltf2 / "TestNoRootNode/SceneWithoutNodes.gltf", "empty");
  fs::path dir = test::scratchDir("cli-json");
  std::ofstream(dir / "broken.gltf") << "{ \"asset\": { \"version\": \"2.0\" ";
  expectCleanFailure(dir / "broken.gltf", "malformed");
  // Truncated binary glTF.
  fs::path glb = kGltf2 / "BoxTextured-glTF-Binary/BoxTextured.glb";
  fs::copy_file(glb, dir / "truncated.glb");
  fs::resize_file(dir / "truncated.glb", fs::file_size(glb) / 2);
  expectCleanFailure(dir / "truncated.glb", "truncated");
}

TEST(Cli, BadVdbInputsFailWithOneLineAndNoOutput) {
  SDFSTREAM_REQUIRE_SHARED_DATA("vdb/smoke.vdb");
  expectCleanFailure(test::sharedData() / "vdb/smoke.vdb", "not-level-set");
  expectCleanFailure(test::sharedData() / "vdb/points.vdb", "not-level-set");
  fs::path dir = test::scratchDir("cli-vdb");
  fs::copy_file(test::sharedData() / "vdb/sphere.vdb", dir / "cut.vdb");
  fs::resize_file(dir / "cut.vdb", fs::file_size(dir / "cut.vdb") / 3);
  expectCleanFailure(dir / "cut.vdb", "truncated");
}

TEST(Cli, VoxelSizeOverMemoryLimitIsRefused) {
  fs::path out = test::scratchDir("cli-big") / "world";
  RunResult r = run("import " + (kGltf2 / "BoxTextured-glTF-Binary/BoxTextured.glb").string() +
                    " -o " + out.string() + " --voxel 0.00001");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.err.find("[too-large]"), std::string::npos) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, FailedImportKeepsAnExistingWorld) {
  fs::path dir = test::scratchDir("cli-keep");
  fs::path world = dir / "world";
  RunResult ok = run("import " + (kGltf2 / "BoxTextured-glTF-Binary/BoxTextured.glb").string() +
                     " -o " + world.string());
  ASSERT_EQ(ok.exitCode, 0) << ok.err;
  ASSERT_TRUE(fs::exists(world / "manifest.json"));
  ASSERT_FALSE(fs::is_empty(world / "tiles"));
  std::string bytes = packBytes(world);
  RunResult bad =
      run("import " + (kGltf2 / "MissingBin/BoxTextured.gltf").string() + " -o " + world.string());
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_EQ(bytes, packBytes(world));
  int entries = 0;
  for (auto& e : fs::directory_iterator(dir)) entries += e.path().filename() == "world" ? 0 : 1;
  EXPECT_EQ(entries, 0) << "no temp directories left behind";
}

TEST(Cli, ImportRenderInfoAndHelp) {
  fs::path dir = test::scratchDir("cli-render");
  RunResult imp = run("import " + (kGltf2 / "BoxTextured-glTF-Binary/BoxTextured.glb").string() +
                      " -o " + (dir / "world").string());
  ASSERT_EQ(imp.exitCode, 0) << imp.err;
  RunResult info = run("info " + (dir / "world").string());
  EXPECT_EQ(info.exitCode, 0) << info.err;
  EXPECT_NE(info.out.find("checksums  ok"), std::string::npos) << info.out;
  // Two short GI frames: the default 24 converge the probes but cost a minute on lavapipe.
  RunResult render =
      run("render " + (dir / "world").string() + " -o " + (dir / "box.png").string() +
          " --width 64 --height 48 --gi-frames 2 --probe-rays 32");
  EXPECT_EQ(render.exitCode, 0) << render.err;
  // scripts/test exports SDFSTREAM_VALIDATION=1: any validation message would land on stderr.
  EXPECT_EQ(render.err, "");
  EXPECT_TRUE(fs::exists(dir / "box.png"));
  EXPECT_NE(render.out.find("rays hit"), std::string::npos);
  RunResult verify = run("verify " + (dir / "world").string());
  EXPECT_EQ(verify.exitCode, 0) << verify.err;
  EXPECT_EQ(verify.out.rfind("ok: ", 0), 0u) << verify.out;
  for (const char* cmd : {"import", "render", "info", "verify", "merge", "demo"}) {
    RunResult help = run(std::string(cmd) + " --help");
    EXPECT_EQ(help.exitCode, 0) << cmd;
    EXPECT_NE(help.out.find("usage: sdfstream"), std::string::npos) << cmd;
  }
  RunResult bogus = run("render " + (dir / "world").string() + " -o x.png --camera 1,2");
  EXPECT_EQ(bogus.exitCode, 2);
  EXPECT_EQ(lineCount(bogus.err), 1);
}

// The GI flags of the rendering commands: render shades with and without GI, writes the direct and
// indirect layers, and rejects bad values with one line (exit 2).
TEST(Cli, RenderGiFlags) {
  fs::path dir = test::scratchDir("cli-gi");
  RunResult imp = run("import " + (kGltf2 / "BoxTextured-glTF-Binary/BoxTextured.glb").string() +
                      " -o " + (dir / "world").string());
  ASSERT_EQ(imp.exitCode, 0) << imp.err;
  const std::string world = (dir / "world").string();
  RunResult off =
      run("render " + world + " -o " + (dir / "off.png").string() +
          " --gi off --layers --width 48 --height 36 --sun 0.3,-1,-0.2,2 --sky 0.1,0.2,0.4");
  EXPECT_EQ(off.exitCode, 0) << off.err;
  EXPECT_EQ(off.err, "");
  EXPECT_EQ(off.out.find("GI "), std::string::npos) << off.out;
  RunResult on = run("render " + world + " -o " + (dir / "on.png").string() +
                     " --gi on --gi-frames 2 --probe-rays 16 --layers --width 48 --height 36 "
                     "--exposure -0.5");
  EXPECT_EQ(on.exitCode, 0) << on.err;
  EXPECT_EQ(on.err, "");  // no validation message (scripts/test sets SDFSTREAM_VALIDATION=1)
  EXPECT_NE(on.out.find("GI 2 frames"), std::string::npos) << on.out;
  for (const char* f : {"off.png", "off-direct.png", "off-indirect.png", "on.png", "on-direct.png",
                        "on-indirect.png"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  for (const std::string bad :
       {"--gi maybe", "--cpu --gi on", "--sun 1,2", "--sky 1,2,3,4", "--direct sometimes",
        "--probe-rays 0", "--cards maybe", "--relight-pages 0", "--relight-pages some"}) {
    RunResult r = run("render " + world + " -o " + (dir / "bad.png").string() + " " + bad);
    EXPECT_EQ(r.exitCode, 2) << bad;
    EXPECT_EQ(lineCount(r.err), 1) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "bad.png")) << bad;
  }
  for (const char* cmd : {"render", "demo", "fly"}) {
    RunResult help = run(std::string(cmd) + " --help");
    EXPECT_EQ(help.exitCode, 0) << cmd;
    for (const char* flag : {"--gi on|off", "--gi-frames", "--probe-rays", "--sun", "--sky",
                             "--cards on|off", "--relight-pages N|all"})
      EXPECT_NE(help.out.find(flag), std::string::npos) << cmd << " --help lacks " << flag;
  }
}

// fly's light-cache budget: a number, or "all" for every out-of-date page each frame, as its
// summary reports it.
TEST(Cli, FlyRelightBudgetReachesTheSummary) {
  fs::path dir = test::scratchDir("cli-relight");
  RunResult imp = run("import " + (kGltf2 / "BoxTextured-glTF-Binary/BoxTextured.glb").string() +
                      " -o " + (dir / "world").string());
  ASSERT_EQ(imp.exitCode, 0) << imp.err;
  for (const std::string budget : {"7", "all"}) {
    const fs::path out = dir / ("fly-" + budget);
    RunResult fly = run("fly " + (dir / "world").string() + " -o " + out.string() +
                        " --frames 2 --width 16 --height 16 --objects 0 --probe-budget 256 "
                        "--cascades 1 --relight-pages " +
                        budget);
    ASSERT_EQ(fly.exitCode, 0) << fly.err;
    std::ifstream in(out / "summary.md");
    const std::string md{std::istreambuf_iterator<char>(in), {}};
    const std::string expected =
        budget == "all" ? "every out-of-date page each frame" : "Budget: 7 pages per frame";
    EXPECT_NE(md.find(expected), std::string::npos) << budget << ":\n" << md;
  }
}


TEST(Cli, SunSweepReachesTheSummaryAndMisuseIsOneLine) {
  fs::path dir = test::scratchDir("cli-sun-sweep");
  RunResult imp = run("import " + (kGltf2 / "BoxTextured-glTF-Binary/BoxTextured.glb").string() +
                      " -o " + (dir / "world").string());
  ASSERT_EQ(imp.exitCode, 0) << imp.err;
  const std::string fly = "fly " + (dir / "world").string() + " -o " + (dir / "fly").string() +
                          " --frames 2 --width 16 --height 16 --objects 0 --probe-budget 256 "
                          "--cascades 1 --sun-sweep ";
  RunResult good = run(fly + "35:3");
  ASSERT_EQ(good.exitCode, 0) << good.err;
  std::ifstream in(dir / "fly" / "summary.md");
  const std::string md{std::istreambuf_iterator<char>(in), {}};
  EXPECT_NE(md.find("sun from 35 to 3 degrees elevation"), std::string::npos) << md;
  for (const std::string bad : {"35", "35:x", "35:3:1", "120:3"}) {
    RunResult r = run(fly + bad);
    EXPECT_NE(r.exitCode, 0) << bad;
    EXPECT_EQ(lineCount(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("--sun-sweep"), std::string::npos) << r.err;
  }
}

TEST(Cli, GenerateWorldRefusesSettlementsWithoutRoom) {
  if (!fs::exists("/usr/share/games/trigger-rally/data.zip"))
    GTEST_SKIP() << "skipped: trigger-rally-data is not installed (scripts/setup installs it)";
  fs::path dir = test::scratchDir("cli-generate-small") / "layout";
  RunResult r = run("generate-world -o " + dir.string() + " --size-km 1");
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--no-settlements"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "layout.json"));
  RunResult plain = run("generate-world -o " + dir.string() + " --size-km 1 --no-settlements");
  EXPECT_EQ(plain.exitCode, 0) << plain.err;
  EXPECT_TRUE(fs::exists(dir / "layout.json"));
  EXPECT_FALSE(fs::exists(dir / "flight.txt"));
}

}  // namespace
}  // namespace sdfstream
