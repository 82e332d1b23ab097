// An installed or packaged sdfstream finds the built-in scene beside itself, not in the source
// tree: the binary is copied into an install layout (bin/ + share/sdfstream/) and into the
// package layout of scripts/package-gpu (the binary + share/sdfstream/), each with a scene that
// does not parse, so `demo` fails at once naming the copy it found.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "tests/support/run_cli.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

// Copies the built binary to `binary` and a malformed scene to `scene`; runs demo there.
test::CliResult demoFrom(const fs::path& binary, const fs::path& scene, const fs::path& out) {
  fs::create_directories(binary.parent_path());
  fs::copy_file(SDFSTREAM_CLI, binary, fs::copy_options::overwrite_existing);
  fs::create_directories(scene.parent_path());
  std::ofstream(scene) << "{ not json\n";
  return test::runCli(binary.string(), "demo --cpu -o " + out.string());
}

TEST(DefaultSceneCli, InstalledBinaryReadsShareSdfstream) {
  const fs::path root = test::scratchDir("installed");
  const fs::path scene = root / "share" / "sdfstream" / "default_scene.json";
  const test::CliResult r = demoFrom(root / "bin" / "sdfstream", scene, root / "out");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find(scene.string()), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("importing " + scene.string()), std::string::npos) << r.out;
}

TEST(DefaultSceneCli, PackagedBinaryReadsItsOwnShareFolder) {
  const fs::path root = test::scratchDir("packaged");
  const fs::path scene = root / "sdfstream-gpu" / "share" / "sdfstream" / "default_scene.json";
  const test::CliResult r = demoFrom(root / "sdfstream-gpu" / "sdfstream", scene, root / "out");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find(scene.string()), std::string::npos) << r.err;
}

}  // namespace
}  // namespace sdfstream
