// Where the built-in demo scene is looked for (demo/default_scene.h): the install layout first,
// then the package layout, then the source tree; and an error naming every place when none has
// it.
#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "demo/default_scene.h"
#include "tests/support/test_data.h"

namespace sdfstream {
namespace {
namespace fs = std::filesystem;

void touch(const fs::path& file) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << "{}\n";
}

TEST(DefaultScene, CandidatesAreInstallThenPackageThenSourceTree) {
  const auto c = defaultSceneCandidates("/opt/sdf/bin/sdfstream");
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].lexically_normal(), fs::path("/opt/sdf/share/sdfstream/default_scene.json"));
  EXPECT_EQ(c[1].lexically_normal(), fs::path("/opt/sdf/bin/share/sdfstream/default_scene.json"));
  EXPECT_EQ(c[2], fs::path(SDFSTREAM_SOURCE_DIR) / "demo" / "default_scene.json");
  EXPECT_TRUE(fs::is_regular_file(c[2]));
}

TEST(DefaultScene, InstallLayoutWinsOverPackageLayout) {
  const fs::path root = test::scratchDir("default-scene-install");
  touch(root / "share" / "sdfstream" / "default_scene.json");
  touch(root / "bin" / "share" / "sdfstream" / "default_scene.json");
  EXPECT_EQ(findDefaultScene(defaultSceneCandidates(root / "bin" / "sdfstream")),
            root / "share" / "sdfstream" / "default_scene.json");
}

TEST(DefaultScene, PackageLayoutIsFoundBesideTheExecutable) {
  const fs::path root = test::scratchDir("default-scene-package");
  touch(root / "share" / "sdfstream" / "default_scene.json");
  EXPECT_EQ(findDefaultScene(defaultSceneCandidates(root / "sdfstream")),
            root / "share" / "sdfstream" / "default_scene.json");
}

TEST(DefaultScene, SourceTreeIsTheLastFallback) {
  const fs::path root = test::scratchDir("default-scene-none");
  EXPECT_EQ(findDefaultScene(defaultSceneCandidates(root / "bin" / "sdfstream")),
            (fs::path(SDFSTREAM_SOURCE_DIR) / "demo" / "default_scene.json").lexically_normal());
}

TEST(DefaultScene, NoneFoundNamesEveryPlaceLooked) {
  const fs::path root = test::scratchDir("default-scene-missing");
  const std::vector<fs::path> places = {root / "a.json", root / "b" / "c.json"};
  try {
    findDefaultScene(places);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.kind(), InputErrorKind::MissingData);
    for (const fs::path& p : places)
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sdfstream
