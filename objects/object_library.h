// The meshes moving objects may use, by index: each one's local SDF (object_sdf.h) built once and
// optionally cached on disk. Instances (instance_set.h) refer to meshes by the index add returns.
#pragma once

#include <cstdint>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

#include "objects/object_sdf.h"
#include "world/triangle_scene.h"

namespace sdfstream {

// Not thread-safe (one owner, usually the frame loop). References returned by mesh() and name()
// stay valid for the library's lifetime (adds never move earlier meshes).
class ObjectLibrary {
 public:
  // Counts of how meshes were obtained, so tests can tell a cache hit without timing.
  struct CacheStats {
    std::uint64_t built = 0;        // buildObjectSdf calls (misses, corrupt files, no cache)
    std::uint64_t loaded = 0;       // meshes read from a valid cache file
    std::uint64_t corrupt = 0;      // cache files found unusable and rebuilt (warned on stderr)
    std::uint64_t writeFailed = 0;  // cache files that could not be written (warned on stderr)
  };

  // cacheDir empty = no disk cache; otherwise created on first write if missing.
  explicit ObjectLibrary(ObjectSdfSettings settings = {}, std::filesystem::path cacheDir = {});

  // Builds mesh's SDF (or loads it from cacheDir/objectCacheFileName(objectCacheKey(mesh,
  // settings))) and returns its index. Cache writes are atomic (temp file + rename); an unusable
  // cache file is rebuilt and replaced, with one warning line on stderr. Throws the InputErrors
  // of buildObjectSdf (file = mesh.source); a failed cache write only warns.
  std::uint32_t add(std::string name, const TriangleScene& mesh);
  // Built-in closed meshes (primitive_meshes.h), centred on the object origin. Named
  // "box(hx,hy,hz)" / "sphere(r)". Invalid sizes: std::invalid_argument.
  std::uint32_t addBox(glm::vec3 halfExtents, glm::vec4 linearAlbedo,
                       glm::vec3 emission = glm::vec3(0.0f));
  std::uint32_t addSphere(float radius, glm::vec4 linearAlbedo, std::uint32_t segments = 24);
  // Every triangle of a glTF file as one mesh (loadGltf's errors), object space = the file's
  // space. Named after the file name.
  std::uint32_t addGltf(const std::filesystem::path& file);

  std::size_t size() const { return meshes_.size(); }
  // i < size(), else std::out_of_range.
  const ObjectSdf& mesh(std::uint32_t i) const { return meshes_.at(i).sdf; }
  const std::string& name(std::uint32_t i) const { return meshes_.at(i).name; }
  // The triangles mesh i was built from (object space): what its cards are captured from.
  const TriangleScene& triangles(std::uint32_t i) const { return meshes_.at(i).triangles; }
  // First mesh with this name, if any (lets spreadObjects reuse its primitives across calls).
  std::optional<std::uint32_t> find(std::string_view name) const;
  // Increments on every add, so the GPU atlas knows to re-upload.
  std::uint64_t version() const { return version_; }
  const ObjectSdfSettings& settings() const { return settings_; }
  const CacheStats& cacheStats() const { return stats_; }

 private:
  struct Entry {
    std::string name;
    ObjectSdf sdf;
    TriangleScene triangles;
  };
  ObjectSdf loadOrBuild(const TriangleScene& mesh);

  ObjectSdfSettings settings_;
  std::filesystem::path cacheDir_;
  std::deque<Entry> meshes_;
  std::uint64_t version_ = 0;
  CacheStats stats_;
};

}  // namespace sdfstream
