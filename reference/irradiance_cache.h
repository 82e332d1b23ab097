// Disk cache of reference irradiance, keyed by scene hash so that benchmarks do not recompute
// it.
//
// The key is an XXH3 (core/hash.h checksum64) of everything the estimate depends on: the scene's
// geometry, UVs, per-triangle materials and textures (material names excluded), the lights and
// sky, the tracer settings (maxDepth, rrStartDepth, seed), the query points and normals, the
// sample count, the kind and kCacheFormatVersion. One file per key:
// <cacheDir>/irradiance-<key as 16 hex digits>.bin. Bump kCacheFormatVersion whenever the
// estimator's results change (e.g. a sampling change), so that old files are never reused.
//
// File layout (host byte order, little-endian on every supported target):
//   bytes 0..7    magic "SDFPTIRR"
//   bytes 8..11   u32 format version       bytes 12..15  u32 kind
//   bytes 16..23  u64 key                  bytes 24..31  u64 point count N
//   bytes 32..39  u64 XXH3 of the payload
//   bytes 40..    N records of 28 bytes: mean (3 × f32), halfWidth95 (3 × f32), samples (u32)
// The file is untrusted on load: a wrong size, magic, version, kind, key, count or checksum makes
// it invalid; it is then recomputed and rewritten, never used. Writes are atomic
// (core/atomic_dir.h writeFileAtomically), so a crash leaves the old file or none.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "reference/path_tracer.h"

namespace sdfstream::reference {

inline constexpr std::uint32_t kCacheFormatVersion = 1;

enum class CacheOutcome {
  Computed,    // no file for the key: computed and stored
  Loaded,      // a valid file was read; nothing was traced
  Recomputed,  // a file existed but was invalid (truncated, corrupted): computed and rewritten
};

// The cache key of a query (see the header comment for what it covers).
std::uint64_t irradianceCacheKey(const PathTracer& tracer, std::span<const glm::vec3> positions,
                                 std::span<const glm::vec3> normals, std::uint32_t samples,
                                 IrradianceKind kind);

// Where the query's file lives in cacheDir.
std::filesystem::path irradianceCachePath(const std::filesystem::path& cacheDir,
                                          const PathTracer& tracer,
                                          std::span<const glm::vec3> positions,
                                          std::span<const glm::vec3> normals, std::uint32_t samples,
                                          IrradianceKind kind);

// tracer.irradiance(positions, normals, samples, kind), read from cacheDir when a valid file for
// the key exists, otherwise computed and written there (cacheDir is created if missing).
// Throws InputError (core/error.h) when the file cannot be written, and std::invalid_argument as
// PathTracer::irradiance does.
std::vector<IrradianceEstimate> cachedIrradiance(const std::filesystem::path& cacheDir,
                                                 const PathTracer& tracer,
                                                 std::span<const glm::vec3> positions,
                                                 std::span<const glm::vec3> normals,
                                                 std::uint32_t samples, IrradianceKind kind,
                                                 CacheOutcome* outcome = nullptr);

}  // namespace sdfstream::reference
