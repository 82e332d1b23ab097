// What every libFuzzer target here shares (one target per reader of untrusted bytes, STYLE.md
// habit 10; scripts/fuzz builds and runs them).
//
// The rule: InputError (core/error.h) is the expected answer to bad bytes and the only exception
// a target catches. Anything else escaping a reader (another exception type, a crash, a leak, UB,
// a hang, an allocation over libFuzzer's limit) is a finding, and so is a returned value that
// breaks what the reader's header promises (checked by contract()).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <unistd.h>

#include "core/error.h"
#include "world/triangle_scene.h"

namespace sdfstream::fuzz {

// Aborts, which libFuzzer reports as a crash with the input saved, when a reader's result breaks
// its documented contract.
inline void contract(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "sdfstream fuzz: contract broken: %s\n", what);
  std::abort();
}

// Runs one reader; only InputError is swallowed.
template <class F>
void expectOnlyInputError(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    // A one-line message naming the file is part of InputError's contract (core/error.h).
    // The message goes to the log first: it shows which untrusted text reached it.
    if (std::string(e.what()).find('\n') != std::string::npos)
      std::fprintf(stderr, "sdfstream fuzz: message: %s\n", e.what());
    contract(std::string(e.what()).find('\n') == std::string::npos, "InputError spans lines");
  }
}

// This process's scratch directory, for readers that take a path. Under $SDFSTREAM_FUZZ_TMP when
// set (scripts/fuzz points it at a folder it removes afterwards), else /dev/shm (tmpfs: the input
// file is rewritten thousands of times a second), else the system temp directory. Removed at a
// normal exit; one per process so parallel jobs (-jobs=N) never share files.
class ScratchDir {
 public:
  ScratchDir() {
    std::filesystem::path base;
    std::error_code ec;
    if (const char* env = std::getenv("SDFSTREAM_FUZZ_TMP"); env && *env)
      base = env;
    else if (std::filesystem::is_directory("/dev/shm", ec))
      base = "/dev/shm";
    else
      base = std::filesystem::temp_directory_path();
    path_ = base / ("sdfstream-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline const std::filesystem::path& scratchDir() {
  static const ScratchDir dir;
  return dir.path();
}

// Writes bytes to scratchDir()/relative (parent folders created) and returns the path.
inline std::filesystem::path writeFile(const std::filesystem::path& relative, const void* data,
                                       std::size_t size) {
  const std::filesystem::path path = scratchDir() / relative;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), std::streamsize(size));
  out.close();
  contract(bool(out), "cannot write the fuzz input to the scratch directory");
  return path;
}

// What every importer promises about the TriangleScene it returns (world/triangle_scene.h):
// indices inside their arrays, one UV per position, one material per triangle, texture sizes
// that match their pixels; finite positions where the importer checks them.
inline void checkScene(const TriangleScene& s, bool positionsFinite) {
  contract(s.uvs.size() == s.positions.size(), "one UV per position");
  contract(s.triangleMaterial.size() == s.triangles.size(), "one material per triangle");
  for (const glm::uvec3& t : s.triangles)
    contract(t.x < s.positions.size() && t.y < s.positions.size() && t.z < s.positions.size(),
             "triangle index inside positions");
  for (std::uint32_t m : s.triangleMaterial)
    contract(m < s.materials.size(), "triangle material inside materials");
  for (const Material& m : s.materials) {
    contract(m.baseColorTexture >= -1 && m.baseColorTexture < int(s.textures.size()),
             "base colour texture index");
    contract(m.emissiveTexture >= -1 && m.emissiveTexture < int(s.textures.size()),
             "emissive texture index");
  }
  for (const Texture& t : s.textures)
    contract(t.width > 0 && t.height > 0 &&
                 t.rgba.size() == std::size_t(t.width) * std::size_t(t.height) * 4,
             "texture pixels match its size");
  if (positionsFinite)
    for (const glm::vec3& p : s.positions)
      contract(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), "finite position");
}

// Samples the materials of the first triangles the way the SDF builder and the path tracer do,
// so texture look-ups driven by the file's UVs and indices run under ASan too.
inline void sampleMaterials(const TriangleScene& s) {
  const std::size_t n = std::min<std::size_t>(s.triangles.size(), 64);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec4 a = sampleAlbedo(s, std::uint32_t(i), glm::vec2(1.0f / 3.0f));
    const glm::vec3 e = sampleEmission(s, std::uint32_t(i), glm::vec2(1.0f / 3.0f));
    (void)a;
    (void)e;
  }
}

}  // namespace sdfstream::fuzz
