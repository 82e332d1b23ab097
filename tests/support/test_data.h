// Where tests find real data. ../shared/data exists beside the project in CI and for developers,
// never on a user's machine: tests that need it call SDFSTREAM_REQUIRE_SHARED_DATA() and skip with
// a message when it is absent. Debian-packaged models (assimp-testmodels, glmark2-data) are
// installed by scripts/setup, so tests may rely on them.
#pragma once

#include <filesystem>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>

namespace sdfstream::test {

inline std::filesystem::path sourceDir() { return SDFSTREAM_SOURCE_DIR; }

inline std::filesystem::path sharedData() {
  if (const char* env = std::getenv("SDFSTREAM_SHARED_DATA")) return env;
  return sourceDir().parent_path() / "shared" / "data";
}

inline std::filesystem::path assimpModels() { return "/usr/share/assimp/models"; }

// A fresh empty directory under the build tree's temp area, removed at the end of the test run.
inline std::filesystem::path scratchDir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() /
             ("sdfstream-test-" + std::to_string(::getpid()) + "-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace sdfstream::test

#define SDFSTREAM_REQUIRE_SHARED_DATA(relative)                                             \
  do {                                                                                      \
    if (!std::filesystem::exists(::sdfstream::test::sharedData() / (relative)))            \
      GTEST_SKIP() << "skipped: " << (::sdfstream::test::sharedData() / (relative)).string() \
                   << " is absent (../shared/data is only present in CI and dev checkouts)"; \
  } while (0)
