#include "reference/irradiance_cache.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>

#include "core/atomic_dir.h"
#include "core/hash.h"
#include "core/read_file.h"

namespace sdfstream::reference {
namespace {

constexpr char kMagic[8] = {'S', 'D', 'F', 'P', 'T', 'I', 'R', 'R'};
constexpr std::size_t kHeaderBytes = 40;
constexpr std::size_t kRecordBytes = 28;

// Appends values' bytes; the key hashes a list of field hashes so that big arrays are hashed in
// place rather than copied.
struct KeyBuilder {
  std::vector<std::uint64_t> parts;
  template <class T>
  void array(const std::vector<T>& v) {
    parts.push_back(v.size());
    parts.push_back(checksum64(v.data(), v.size() * sizeof(T)));
  }
  void span(std::span<const glm::vec3> v) {
    parts.push_back(v.size());
    parts.push_back(checksum64(v.data(), v.size_bytes()));
  }
  void f(float x) {
    std::uint32_t bits;
    std::memcpy(&bits, &x, 4);
    parts.push_back(bits);
  }
  void v3(const glm::vec3& x) {
    f(x.x);
    f(x.y);
    f(x.z);
  }
  void u(std::uint64_t x) { parts.push_back(x); }
  std::uint64_t finish() const { return checksum64(parts.data(), parts.size() * 8); }
};

// glm vectors must be tightly packed for the byte hashes and the file records to mean anything.
static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::vec2) == 8 && sizeof(glm::uvec3) == 12);

void hashScene(KeyBuilder& k, const TriangleScene& s) {
  k.array(s.positions);
  k.array(s.uvs);
  k.array(s.triangles);
  k.array(s.triangleMaterial);
  k.u(s.materials.size());
  for (const Material& m : s.materials) {  // field by field: Material has padding and a name
    k.v3(glm::vec3(m.baseColorFactor));
    k.f(m.baseColorFactor.w);
    k.u(std::uint64_t(std::int64_t(m.baseColorTexture)));
    k.u(std::uint64_t(std::int64_t(m.baseColorTexCoord)));
    k.v3(m.emissive);
    k.u(std::uint64_t(std::int64_t(m.emissiveTexture)));
    // Later fields only when they differ from their defaults, so existing caches stay valid.
    if (m.emissiveTexCoord != 0 || !m.baseColorUv.isIdentity() || !m.emissiveUv.isIdentity()) {
      k.u(std::uint64_t(std::int64_t(m.emissiveTexCoord)));
      for (const UvTransform* t : {&m.baseColorUv, &m.emissiveUv})
        for (const glm::vec2 v : {t->column0, t->column1, t->offset}) k.v3(glm::vec3(v, 0.0f));
    }
  }
  if (!s.uvs1.empty()) k.array(s.uvs1);
  k.u(s.textures.size());
  for (const Texture& t : s.textures) {
    k.u(std::uint64_t(std::int64_t(t.width)));
    k.u(std::uint64_t(std::int64_t(t.height)));
    k.array(t.rgba);
  }
}

void hashLights(KeyBuilder& k, const SceneLights& l) {
  k.u(l.lights.size());
  for (const SceneLight& light : l.lights) {  // `version` is excluded: it counts edits only
    k.u(std::uint64_t(light.type));
    for (int i = 0; i < 3; ++i) {  // the doubles themselves, not their float rounding
      std::uint64_t bits;
      std::memcpy(&bits, &light.position[i], 8);
      k.u(bits);
    }
    k.v3(light.direction);
    k.v3(light.color);
    k.f(light.intensity);
    k.f(light.innerConeDegrees);
    k.f(light.outerConeDegrees);
    k.f(light.range);
    k.f(light.shadowSharpness);
    k.u(light.castsShadows ? 1u : 0u);
  }
  k.v3(l.sky.zenith);
  k.v3(l.sky.horizon);
}

std::vector<char> readAll(const std::filesystem::path& path) {
  return tryReadWholeFile<std::vector<char>>(path).value_or(std::vector<char>{});
}

template <class T>
T readAt(const std::vector<char>& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

// The estimates stored in `bytes`, or nullopt when anything about them is off.
std::optional<std::vector<IrradianceEstimate>> parse(const std::vector<char>& bytes,
                                                     std::uint64_t key, IrradianceKind kind,
                                                     std::size_t count) {
  if (bytes.size() != kHeaderBytes + count * kRecordBytes) return std::nullopt;
  if (std::memcmp(bytes.data(), kMagic, 8) != 0) return std::nullopt;
  if (readAt<std::uint32_t>(bytes, 8) != kCacheFormatVersion) return std::nullopt;
  if (readAt<std::uint32_t>(bytes, 12) != std::uint32_t(kind)) return std::nullopt;
  if (readAt<std::uint64_t>(bytes, 16) != key) return std::nullopt;
  if (readAt<std::uint64_t>(bytes, 24) != count) return std::nullopt;
  const char* payload = bytes.data() + kHeaderBytes;
  if (readAt<std::uint64_t>(bytes, 32) != checksum64(payload, count * kRecordBytes))
    return std::nullopt;
  std::vector<IrradianceEstimate> out(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t at = kHeaderBytes + i * kRecordBytes;
    out[i].mean = readAt<glm::vec3>(bytes, at);
    out[i].halfWidth95 = readAt<glm::vec3>(bytes, at + 12);
    out[i].samples = readAt<std::uint32_t>(bytes, at + 24);
  }
  return out;
}

std::vector<char> serialize(const std::vector<IrradianceEstimate>& e, std::uint64_t key,
                            IrradianceKind kind) {
  std::vector<char> bytes(kHeaderBytes + e.size() * kRecordBytes);
  auto put = [&](std::size_t offset, const auto& v) {
    std::memcpy(bytes.data() + offset, &v, sizeof(v));
  };
  std::memcpy(bytes.data(), kMagic, 8);
  put(8, kCacheFormatVersion);
  put(12, std::uint32_t(kind));
  put(16, key);
  put(24, std::uint64_t(e.size()));
  for (std::size_t i = 0; i < e.size(); ++i) {
    const std::size_t at = kHeaderBytes + i * kRecordBytes;
    put(at, e[i].mean);
    put(at + 12, e[i].halfWidth95);
    put(at + 24, e[i].samples);
  }
  put(32, checksum64(bytes.data() + kHeaderBytes, e.size() * kRecordBytes));
  return bytes;
}

}  // namespace

std::uint64_t irradianceCacheKey(const PathTracer& tracer, std::span<const glm::vec3> positions,
                                 std::span<const glm::vec3> normals, std::uint32_t samples,
                                 IrradianceKind kind) {
  KeyBuilder k;
  k.u(kCacheFormatVersion);
  hashScene(k, tracer.scene());
  hashLights(k, tracer.lights());
  k.u(tracer.settings().maxDepth);
  k.u(tracer.settings().rrStartDepth);
  k.u(tracer.settings().seed);
  k.span(positions);
  k.span(normals);
  k.u(samples);
  k.u(std::uint64_t(kind));
  return k.finish();
}

std::filesystem::path irradianceCachePath(const std::filesystem::path& cacheDir,
                                          const PathTracer& tracer,
                                          std::span<const glm::vec3> positions,
                                          std::span<const glm::vec3> normals, std::uint32_t samples,
                                          IrradianceKind kind) {
  return cacheDir / ("irradiance-" +
                     toHex(irradianceCacheKey(tracer, positions, normals, samples, kind)) + ".bin");
}

std::vector<IrradianceEstimate> cachedIrradiance(const std::filesystem::path& cacheDir,
                                                 const PathTracer& tracer,
                                                 std::span<const glm::vec3> positions,
                                                 std::span<const glm::vec3> normals,
                                                 std::uint32_t samples, IrradianceKind kind,
                                                 CacheOutcome* outcome) {
  const std::uint64_t key = irradianceCacheKey(tracer, positions, normals, samples, kind);
  const std::filesystem::path path = cacheDir / ("irradiance-" + toHex(key) + ".bin");
  std::error_code ec;
  const bool existed = std::filesystem::exists(path, ec);
  if (existed) {
    if (auto loaded = parse(readAll(path), key, kind, positions.size())) {
      if (outcome) *outcome = CacheOutcome::Loaded;
      return *std::move(loaded);
    }
  }
  std::vector<IrradianceEstimate> result = tracer.irradiance(positions, normals, samples, kind);
  std::filesystem::create_directories(cacheDir, ec);
  const std::vector<char> bytes = serialize(result, key, kind);
  writeFileAtomically(path, bytes.data(), bytes.size());
  if (outcome) *outcome = existed ? CacheOutcome::Recomputed : CacheOutcome::Computed;
  return result;
}

}  // namespace sdfstream::reference
