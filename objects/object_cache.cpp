#include "objects/object_cache.h"

#include <bit>
#include <cmath>
#include <cstring>

#include "core/hash.h"

namespace sdfstream {
namespace {

constexpr char kMagic[8] = {'S', 'D', 'F', 'O', 'B', 'J', 'C', '\0'};

// The fixed-size part after the magic; every field 4-byte aligned, no padding (asserted).
struct FileHeader {
  std::uint32_t version;
  std::uint32_t keyLo, keyHi;  // the u64 key, split so the struct has no padding
  std::uint32_t dims[3];
  float gridMin[3];
  float voxel;
  float meshMin[3];
  float meshMax[3];
  std::uint32_t closed;
};
static_assert(sizeof(FileHeader) == 68);

template <typename T>
std::uint64_t hashVector(const std::vector<T>& v) {
  return checksum64(v.data(), v.size() * sizeof(T));
}

// Copies count T's to out at offset, returning the offset after them.
template <typename T>
std::size_t put(std::vector<std::uint8_t>& out, std::size_t offset, const T* data,
                std::size_t count) {
  std::memcpy(out.data() + offset, data, count * sizeof(T));
  return offset + count * sizeof(T);
}

}  // namespace

std::uint64_t objectCacheKey(const TriangleScene& mesh, const ObjectSdfSettings& settings) {
  // Hash of hashes: no copy of the (possibly large) texture data into one buffer.
  std::vector<std::uint64_t> parts{
      kObjectCacheVersion,
      settings.minResolution,
      settings.maxResolution,
      settings.padVoxels,
      std::bit_cast<std::uint64_t>(settings.targetVoxel),
      mesh.positions.size(),
      hashVector(mesh.positions),
      mesh.uvs.size(),
      hashVector(mesh.uvs),
      mesh.triangles.size(),
      hashVector(mesh.triangles),
      mesh.triangleMaterial.size(),
      hashVector(mesh.triangleMaterial),
      mesh.materials.size(),
  };
  for (const Material& m : mesh.materials) {
    const float f[7] = {m.baseColorFactor.r, m.baseColorFactor.g, m.baseColorFactor.b,
                        m.baseColorFactor.a, m.emissive.r,        m.emissive.g,
                        m.emissive.b};
    const std::int32_t i[3] = {m.baseColorTexture, m.baseColorTexCoord, m.emissiveTexture};
    parts.push_back(checksum64(f, sizeof f));
    parts.push_back(checksum64(i, sizeof i));
    // Later fields only when they differ from their defaults, so existing caches stay valid.
    if (m.emissiveTexCoord != 0 || !m.baseColorUv.isIdentity() || !m.emissiveUv.isIdentity()) {
      const float t[13] = {m.baseColorUv.column0.x, m.baseColorUv.column0.y,
                           m.baseColorUv.column1.x, m.baseColorUv.column1.y,
                           m.baseColorUv.offset.x,  m.baseColorUv.offset.y,
                           m.emissiveUv.column0.x,  m.emissiveUv.column0.y,
                           m.emissiveUv.column1.x,  m.emissiveUv.column1.y,
                           m.emissiveUv.offset.x,   m.emissiveUv.offset.y,
                           float(m.emissiveTexCoord)};
      parts.push_back(checksum64(t, sizeof t));
    }
  }
  if (!mesh.uvs1.empty()) {
    parts.push_back(mesh.uvs1.size());
    parts.push_back(hashVector(mesh.uvs1));
  }
  parts.push_back(mesh.textures.size());
  for (const Texture& t : mesh.textures) {
    parts.push_back(std::uint64_t(std::uint32_t(t.width)) << 32 | std::uint32_t(t.height));
    parts.push_back(t.rgba.size());
    parts.push_back(hashVector(t.rgba));
  }
  return checksum64(parts.data(), parts.size() * sizeof(std::uint64_t));
}

std::string objectCacheFileName(std::uint64_t key) { return toHex(key) + ".osdf"; }

std::vector<std::uint8_t> serializeObjectSdf(const ObjectSdf& sdf, std::uint64_t key) {
  FileHeader h{};
  h.version = kObjectCacheVersion;
  h.keyLo = std::uint32_t(key);
  h.keyHi = std::uint32_t(key >> 32);
  for (int a = 0; a < 3; ++a) {
    h.dims[a] = sdf.dims[a];
    h.gridMin[a] = sdf.gridMin[a];
    h.meshMin[a] = sdf.meshMin[a];
    h.meshMax[a] = sdf.meshMax[a];
  }
  h.voxel = sdf.voxel;
  h.closed = sdf.closed ? 1u : 0u;
  const std::size_t n = sdf.sampleCount();
  std::vector<std::uint8_t> out(sizeof kMagic + sizeof h + n * 12 + 8);
  std::size_t at = put(out, 0, kMagic, sizeof kMagic);
  at = put(out, at, &h, 1);
  at = put(out, at, sdf.distance.data(), n);
  at = put(out, at, sdf.albedo.data(), n);
  at = put(out, at, sdf.emission.data(), n);
  const std::uint64_t sum = checksum64(out.data(), at);
  put(out, at, &sum, 1);
  return out;
}

std::optional<ObjectSdf> parseObjectSdf(std::span<const std::uint8_t> bytes, std::uint64_t key,
                                        std::string* problem) {
  auto fail = [&](const char* why) -> std::optional<ObjectSdf> {
    if (problem) *problem = why;
    return std::nullopt;
  };
  constexpr std::size_t kFixed = sizeof kMagic + sizeof(FileHeader);
  if (bytes.size() < kFixed + 8) return fail("shorter than its header");
  if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) return fail("bad magic");
  FileHeader h;
  std::memcpy(&h, bytes.data() + sizeof kMagic, sizeof h);
  if (h.version != kObjectCacheVersion) return fail("other cache version");
  if ((std::uint64_t(h.keyHi) << 32 | h.keyLo) != key) return fail("key does not match its name");
  for (std::uint32_t d : h.dims)
    if (d < 2 || d > 4096) return fail("dims outside 2..4096");
  const std::size_t n = std::size_t(h.dims[0]) * h.dims[1] * h.dims[2];
  if (bytes.size() != kFixed + n * 12 + 8) return fail("size does not match dims");
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  if (checksum64(bytes.data(), bytes.size() - 8) != stored) return fail("checksum mismatch");
  const float fields[10] = {h.gridMin[0], h.gridMin[1], h.gridMin[2], h.voxel,      h.meshMin[0],
                            h.meshMin[1], h.meshMin[2], h.meshMax[0], h.meshMax[1], h.meshMax[2]};
  for (float f : fields)
    if (!std::isfinite(f)) return fail("non-finite grid field");
  if (!(h.voxel > 0.0f)) return fail("voxel not positive");

  ObjectSdf sdf;
  sdf.dims = glm::uvec3(h.dims[0], h.dims[1], h.dims[2]);
  sdf.gridMin = glm::vec3(h.gridMin[0], h.gridMin[1], h.gridMin[2]);
  sdf.voxel = h.voxel;
  sdf.meshMin = glm::vec3(h.meshMin[0], h.meshMin[1], h.meshMin[2]);
  sdf.meshMax = glm::vec3(h.meshMax[0], h.meshMax[1], h.meshMax[2]);
  sdf.closed = h.closed != 0;
  const std::uint8_t* p = bytes.data() + kFixed;
  sdf.distance.resize(n);
  sdf.albedo.resize(n);
  sdf.emission.resize(n);
  std::memcpy(sdf.distance.data(), p, n * 4);
  std::memcpy(sdf.albedo.data(), p + n * 4, n * 4);
  std::memcpy(sdf.emission.data(), p + n * 8, n * 4);
  return sdf;
}

}  // namespace sdfstream
