#include "objects/object_library.h"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "core/atomic_dir.h"
#include "core/read_file.h"
#include "objects/object_cache.h"
#include "objects/primitive_meshes.h"
#include "world/gltf_import.h"

namespace sdfstream {
namespace {

std::string shortFloat(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", double(v));
  return buf;
}

}  // namespace

ObjectLibrary::ObjectLibrary(ObjectSdfSettings settings, std::filesystem::path cacheDir)
    : settings_(settings), cacheDir_(std::move(cacheDir)) {}

std::uint32_t ObjectLibrary::add(std::string name, const TriangleScene& mesh) {
  if (meshes_.size() >= std::size_t(UINT32_MAX)) throw std::length_error("ObjectLibrary full");
  ObjectSdf sdf = loadOrBuild(mesh);
  meshes_.push_back({std::move(name), std::move(sdf), mesh});
  ++version_;
  return std::uint32_t(meshes_.size() - 1);
}

ObjectSdf ObjectLibrary::loadOrBuild(const TriangleScene& mesh) {
  // Validate first even on a hit: a bad mesh must fail the same way with or without a cache.
  validateObjectMesh(mesh);
  if (cacheDir_.empty()) {
    ++stats_.built;
    return buildObjectSdf(mesh, settings_);
  }
  const std::uint64_t key = objectCacheKey(mesh, settings_);
  const std::filesystem::path path = cacheDir_ / objectCacheFileName(key);
  if (auto bytes = tryReadWholeFile<std::vector<std::uint8_t>>(path)) {
    std::string problem;
    if (auto sdf = parseObjectSdf(*bytes, key, &problem)) {
      ++stats_.loaded;
      return std::move(*sdf);
    }
    ++stats_.corrupt;
    std::fprintf(stderr, "sdfstream: object cache %s: %s; rebuilding it\n", path.c_str(),
                 problem.c_str());
  }
  ObjectSdf sdf = buildObjectSdf(mesh, settings_);
  ++stats_.built;
  try {
    std::filesystem::create_directories(cacheDir_);
    const std::vector<std::uint8_t> bytes = serializeObjectSdf(sdf, key);
    writeFileAtomically(path, bytes.data(), bytes.size());
  } catch (const std::exception& e) {  // the cache is an optimisation: keep the built mesh
    ++stats_.writeFailed;
    std::fprintf(stderr, "sdfstream: object cache %s: not written (%s)\n", path.c_str(), e.what());
  }
  return sdf;
}

std::uint32_t ObjectLibrary::addBox(glm::vec3 halfExtents, glm::vec4 linearAlbedo,
                                    glm::vec3 emission) {
  return add("box(" + shortFloat(halfExtents.x) + "," + shortFloat(halfExtents.y) + "," +
                 shortFloat(halfExtents.z) + ")",
             makeBoxMesh(halfExtents, linearAlbedo, emission));
}

std::uint32_t ObjectLibrary::addSphere(float radius, glm::vec4 linearAlbedo,
                                       std::uint32_t segments) {
  return add("sphere(" + shortFloat(radius) + ")", makeSphereMesh(radius, linearAlbedo, segments));
}

std::uint32_t ObjectLibrary::addGltf(const std::filesystem::path& file) {
  return add(file.filename().string(), loadGltf(file));
}

std::optional<std::uint32_t> ObjectLibrary::find(std::string_view name) const {
  for (std::size_t i = 0; i < meshes_.size(); ++i)
    if (meshes_[i].name == name) return std::uint32_t(i);
  return std::nullopt;
}

}  // namespace sdfstream
