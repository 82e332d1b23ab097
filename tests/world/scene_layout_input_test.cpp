// parseLayout (world/scene_layout.h) on hostile layouts, as fuzz/layout_fuzz.cpp feeds it: the
// layout's own keys and file names appear in its errors, which must stay one line (found
// reviewing the parser against the fuzz contract), and every JSON error is an InputError.
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/test_data.h"
#include "world/scene_layout.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

InputError parseError(const std::string& name, const std::string& json) {
  const fs::path path = test::scratchDir("layout-" + name) / "layout.json";
  std::ofstream(path) << json;
  try {
    parseLayout(path);
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path.string());
    return e;
  }
  ADD_FAILURE() << json << " parsed";
  return InputError(InputErrorKind::Io, "", "");
}

// {"a\nb": 1} reported "layout.a<newline>b: unknown key".
TEST(SceneLayoutInput, UnknownKeyWithNewlineKeepsTheErrorOneLine) {
  const InputError e = parseError("key", R"({"boxes": [], "a\nb": 1})");
  const std::string what = e.what();
  EXPECT_EQ(e.kind(), InputErrorKind::Malformed) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  EXPECT_NE(what.find("layout.a\\x0ab: unknown key"), std::string::npos) << what;
}

// The same for a file name that does not exist.
TEST(SceneLayoutInput, MissingAssetNameWithNewlineKeepsTheErrorOneLine) {
  const InputError e = parseError("file", R"({"assets": [{"file": "chair\n.glb"}]})");
  const std::string what = e.what();
  EXPECT_EQ(e.kind(), InputErrorKind::MissingData) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  EXPECT_NE(what.find("chair\\x0a.glb does not exist"), std::string::npos) << what;
}

// Fuzz finding (layout_fuzz, within seconds; the glb target hit the same in the glTF parser):
// nlohmann reports a number too large for a double as out_of_range, not parse_error, so it
// escaped parseLayout as a foreign exception.
TEST(SceneLayoutInput, NumberOverflowIsMalformed) {
  const InputError e = parseError("overflow", R"({"boxes": [{"min": [0, 0, 0], "max": [1e999, 1, 1]}]})");
  EXPECT_EQ(e.kind(), InputErrorKind::Malformed) << e.what();
  EXPECT_NE(std::string(e.what()).find("number overflow"), std::string::npos) << e.what();
}

}  // namespace
}  // namespace sdfstream
