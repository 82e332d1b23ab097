// The object library's disk cache: one file per (mesh, settings) holding a built ObjectSdf, so a
// demo or benchmark restart skips the OpenVDB build. Files are a cache, never a source of truth:
// anything unexpected in one (short, foreign, checksum mismatch) is a miss, not an error.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "objects/object_sdf.h"

namespace sdfstream {

// Bumped whenever the file layout or buildObjectSdf's output for the same input changes.
inline constexpr std::uint32_t kObjectCacheVersion = 1;

// XXH3 over everything buildObjectSdf reads: positions, UVs, triangles, triangle materials,
// material factors and texture indices, texture texels, the settings and kObjectCacheVersion.
// Not the mesh's source or material names (they do not change the SDF).
std::uint64_t objectCacheKey(const TriangleScene& mesh, const ObjectSdfSettings& settings);

// "<16 hex digits of key>.osdf".
std::string objectCacheFileName(std::uint64_t key);

// File layout, host byte order (little-endian on every supported target):
//   "SDFOBJC\0" · u32 version · u64 key · u32 dims[3] · f32 gridMin[3] · f32 voxel ·
//   f32 meshMin[3] · f32 meshMax[3] · u32 closed · f32 distance[n] · u32 albedo[n] ·
//   u32 emission[n] · u64 XXH3 of every byte before it.       (n = dims.x·dims.y·dims.z)
std::vector<std::uint8_t> serializeObjectSdf(const ObjectSdf& sdf, std::uint64_t key);

// The inverse. Safe on untrusted bytes: returns nullopt with a one-phrase reason in *problem for
// a wrong magic, version or key, a size that does not match dims (dims each 2..4096), a
// checksum mismatch, or non-finite grid fields.
std::optional<ObjectSdf> parseObjectSdf(std::span<const std::uint8_t> bytes, std::uint64_t key,
                                        std::string* problem);

}  // namespace sdfstream
