#include "world/world_io.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atomic_dir.h"
#include "core/error.h"
#include "core/hash.h"

namespace sdfstream {
namespace {

static_assert(std::endian::native == std::endian::little, "bricks.bin is little-endian");

constexpr char kMagic[8] = {'S', 'D', 'F', 'B', 'R', 'I', 'C', 'K'};
constexpr int kSections = 4;
constexpr const char* kSectionNames[kSections] = {"coords", "distances", "albedo", "emission"};
constexpr std::uint64_t kPerBrick[kSections] = {
    3 * sizeof(std::int32_t), layout::kBrickSampleCount * sizeof(std::uint16_t),
    layout::kBrickMaterialCount * sizeof(std::uint32_t),
    layout::kBrickMaterialCount * sizeof(std::uint32_t)};
constexpr std::size_t kHeaderSize = 24 + kSections * 24;

struct Section {
  std::uint64_t offset, size, checksum;
};

std::uint64_t align8(std::uint64_t v) { return (v + 7) & ~std::uint64_t(7); }

template <typename T>
void put(std::vector<std::uint8_t>& out, std::size_t at, T v) {
  std::memcpy(out.data() + at, &v, sizeof v);
}
template <typename T>
T get(const std::vector<std::uint8_t>& in, std::size_t at) {
  T v;
  std::memcpy(&v, in.data() + at, sizeof v);
  return v;
}

std::vector<std::uint8_t> encodeBricks(const World& world) {
  const std::uint64_t n = world.bricks.size();
  Section sections[kSections];
  std::uint64_t at = kHeaderSize;
  for (int s = 0; s < kSections; ++s) {
    at = align8(at);
    sections[s] = {at, n * kPerBrick[s], 0};
    at += sections[s].size;
  }
  std::vector<std::uint8_t> out(at, 0);
  for (std::uint64_t i = 0; i < n; ++i) {
    const Brick& b = world.bricks[i];
    const std::int32_t coord[3] = {b.coord.x, b.coord.y, b.coord.z};
    std::memcpy(out.data() + sections[0].offset + i * kPerBrick[0], coord, kPerBrick[0]);
    std::memcpy(out.data() + sections[1].offset + i * kPerBrick[1], b.distance.data(),
                kPerBrick[1]);
    std::memcpy(out.data() + sections[2].offset + i * kPerBrick[2], b.albedo.data(), kPerBrick[2]);
    std::memcpy(out.data() + sections[3].offset + i * kPerBrick[3], b.emission.data(),
                kPerBrick[3]);
  }
  std::memcpy(out.data(), kMagic, 8);
  put<std::uint32_t>(out, 8, kBricksVersion);
  put<std::uint32_t>(out, 12, kSections);
  put<std::uint64_t>(out, 16, n);
  for (int s = 0; s < kSections; ++s) {
    sections[s].checksum = checksum64(out.data() + sections[s].offset, sections[s].size);
    put(out, 24 + s * 24, sections[s].offset);
    put(out, 32 + s * 24, sections[s].size);
    put(out, 40 + s * 24, sections[s].checksum);
  }
  return out;
}

void writeFile(const std::filesystem::path& path, const void* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), std::streamsize(size));
  out.flush();
  if (!out) throw InputError(InputErrorKind::Io, path.string(), "write failed (disk full?)");
}

std::vector<std::uint8_t> readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(InputErrorKind::Io, path.string(), "cannot open");
  std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(in)),
                                 std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(InputErrorKind::Io, path.string(), "read failed");
  return data;
}

nlohmann::json vec3Json(glm::dvec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }
nlohmann::json vec3Json(glm::ivec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

}  // namespace

void writeWorld(const World& world, const std::filesystem::path& dir) {
  const std::vector<std::uint8_t> bricks = encodeBricks(world);
  nlohmann::json j;  // std::map-backed: keys are written sorted, so output is deterministic
  j["format"] = "sdfstream-world";
  j["version"] = kWorldVersion;
  j["source"] = world.source;
  j["voxelSize"] = world.voxelSize;
  j["origin"] = vec3Json(world.origin);
  j["indexMin"] = vec3Json(world.indexMin());
  j["indexMax"] = vec3Json(world.indexMax());
  j["brickCount"] = world.bricks.size();
  j["bricks"] = {{"file", "bricks.bin"},
                 {"bytes", bricks.size()},
                 {"xxh3", toHex(checksum64(bricks.data(), bricks.size()))}};
  const std::string text = j.dump(2) + "\n";

  AtomicDirectory out(dir);
  writeFile(out.staging() / "bricks.bin", bricks.data(), bricks.size());
  writeFile(out.staging() / "world.json", text.data(), text.size());
  out.commit();
}

World readWorld(const std::filesystem::path& dir) {
  const std::filesystem::path jsonPath = dir / "world.json", binPath = dir / "bricks.bin";
  const std::string jsonFile = jsonPath.string(), binFile = binPath.string();
  World world;
  std::uint64_t brickCount = 0, binBytes = 0;
  std::string binChecksum;
  {
    const std::vector<std::uint8_t> text = readFile(jsonPath);
    nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
    if (j.is_discarded() || !j.is_object())
      throw InputError(InputErrorKind::Malformed, jsonFile, "not a JSON object");
    try {
      if (j.at("format").get<std::string>() != "sdfstream-world")
        throw InputError(InputErrorKind::Version, jsonFile, "not an sdfstream world");
      if (j.at("version").get<std::uint32_t>() != kWorldVersion)
        throw InputError(InputErrorKind::Version, jsonFile,
                         "world version " + j.at("version").dump() +
                             " is not supported (expected " + std::to_string(kWorldVersion) + ")");
      world.source = j.at("source").get<std::string>();
      world.voxelSize = j.at("voxelSize").get<double>();
      auto o = j.at("origin").get<std::array<double, 3>>();
      world.origin = {o[0], o[1], o[2]};
      brickCount = j.at("brickCount").get<std::uint64_t>();
      binBytes = j.at("bricks").at("bytes").get<std::uint64_t>();
      binChecksum = j.at("bricks").at("xxh3").get<std::string>();
    } catch (const nlohmann::json::exception& e) {
      throw InputError(InputErrorKind::Malformed, jsonFile, e.what());
    }
    if (!std::isfinite(world.voxelSize) || !(world.voxelSize > 0.0) ||
        !std::isfinite(world.origin.x) || !std::isfinite(world.origin.y) ||
        !std::isfinite(world.origin.z))
      throw InputError(InputErrorKind::NonFinite, jsonFile, "voxelSize/origin not finite");
  }

  const std::vector<std::uint8_t> bin = readFile(binPath);
  if (bin.size() < kHeaderSize)
    throw InputError(InputErrorKind::Truncated, binFile, "shorter than its header");
  if (std::memcmp(bin.data(), kMagic, 8) != 0)
    throw InputError(InputErrorKind::Malformed, binFile, "bad magic (not a bricks file)");
  if (get<std::uint32_t>(bin, 8) != kBricksVersion)
    throw InputError(
        InputErrorKind::Version, binFile,
        "bricks version " + std::to_string(get<std::uint32_t>(bin, 8)) + " is not supported");
  const std::uint64_t n = get<std::uint64_t>(bin, 16);
  if (bin.size() < binBytes)
    throw InputError(
        InputErrorKind::Truncated, binFile,
        std::to_string(bin.size()) + " bytes, world.json declares " + std::to_string(binBytes));
  if (get<std::uint32_t>(bin, 12) != kSections || n != brickCount || n > (1ull << 40))
    throw InputError(InputErrorKind::Malformed, binFile, "header disagrees with world.json");
  Section sections[kSections];
  std::uint64_t expectedOffset = kHeaderSize;
  for (int s = 0; s < kSections; ++s) {
    sections[s] = {get<std::uint64_t>(bin, 24 + s * 24), get<std::uint64_t>(bin, 32 + s * 24),
                   get<std::uint64_t>(bin, 40 + s * 24)};
    expectedOffset = align8(expectedOffset);
    if (sections[s].offset != expectedOffset || sections[s].size != n * kPerBrick[s])
      throw InputError(InputErrorKind::Malformed, binFile,
                       std::string("bad layout of section ") + kSectionNames[s]);
    expectedOffset += sections[s].size;
    if (expectedOffset > bin.size())
      throw InputError(InputErrorKind::Truncated, binFile,
                       std::string("file ends inside section ") + kSectionNames[s] + " (" +
                           std::to_string(bin.size()) + " of " + std::to_string(binBytes) +
                           " bytes)");
  }
  for (int s = 0; s < kSections; ++s)
    if (checksum64(bin.data() + sections[s].offset, sections[s].size) != sections[s].checksum)
      throw InputError(InputErrorKind::Checksum, binFile,
                       std::string("checksum mismatch in section ") + kSectionNames[s]);
  if (bin.size() != binBytes)
    throw InputError(
        bin.size() < binBytes ? InputErrorKind::Truncated : InputErrorKind::Malformed, binFile,
        std::to_string(bin.size()) + " bytes, world.json declares " + std::to_string(binBytes));
  if (toHex(checksum64(bin.data(), bin.size())) != binChecksum)
    throw InputError(InputErrorKind::Checksum, binFile, "checksum mismatch in header");

  world.bricks.resize(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    Brick& b = world.bricks[i];
    std::int32_t coord[3];
    std::memcpy(coord, bin.data() + sections[0].offset + i * kPerBrick[0], kPerBrick[0]);
    b.coord = {coord[0], coord[1], coord[2]};
    std::memcpy(b.distance.data(), bin.data() + sections[1].offset + i * kPerBrick[1],
                kPerBrick[1]);
    std::memcpy(b.albedo.data(), bin.data() + sections[2].offset + i * kPerBrick[2], kPerBrick[2]);
    std::memcpy(b.emission.data(), bin.data() + sections[3].offset + i * kPerBrick[3],
                kPerBrick[3]);
    if (i > 0 && !brickCoordLess(world.bricks[i - 1].coord, b.coord))
      throw InputError(InputErrorKind::Malformed, binFile, "bricks not sorted or not unique");
  }
  return world;
}

}  // namespace sdfstream
