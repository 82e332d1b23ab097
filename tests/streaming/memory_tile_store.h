// In-memory tile stores for streaming tests: procedurally generated tiles (deterministic per
// coordinate), optionally shifted far from the origin, slowed behind a gate, or failing.
#pragma once

#include <atomic>
#include <chrono>
#include <thread>
#include <condition_variable>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>

#include "streaming/cascade_stack.h"
#include "streaming/tile_loader.h"
#include "streaming/tile_store.h"

namespace sdfstream::test {

// The small partition the streaming tests use: 1 m voxels, 3 LODs, 32-voxel tiles (4, 2 and 1
// bricks per tile edge), and matching streaming options (3 cascades, 6,000 atlas slots).
inline PartitionSpec smallTestSpec() {
  PartitionSpec s;
  s.voxelSize = 1.0;
  s.lodCount = 3;
  s.tileVoxels = 32;
  return s;
}
inline StreamingOptions smallTestOptions() {
  StreamingOptions o;
  o.cascades = 3;
  o.atlasSlots = 6000;
  return o;
}

class MemoryTileStore : public TileStore {
 public:
  // Tiles exist for coords in [-range, range]³ where a hash says so (~60%); each LOD holds a
  // few random bricks tagged with their coordinate, and random emptyDistance values.
  MemoryTileStore(PartitionSpec spec, int range, glm::ivec3 shiftTiles = glm::ivec3(0))
      : spec_(spec), range_(range), shift_(shiftTiles) {}

  const PartitionSpec& spec() const override { return spec_; }
  bool hasTile(glm::ivec3 t) const override {
    glm::ivec3 u = t - shift_;
    if (glm::any(glm::greaterThan(glm::abs(u), glm::ivec3(range_)))) return false;
    return hash(u) % 10 < 6;
  }
  std::shared_ptr<const Tile> load(glm::ivec3 t, int /*lod: all are generated*/,
                                   std::size_t* bytesRead) const override {
    if (bytesRead) *bytesRead = 4096;
    ++loads;
    gate();
    if (latencyMs > 0) std::this_thread::sleep_for(std::chrono::milliseconds(latencyMs));
    if (failing.count({t.x, t.y, t.z})) throw std::runtime_error("injected I/O error");
    glm::ivec3 u = t - shift_;
    auto tile = std::make_shared<Tile>();
    tile->coord = t;
    std::mt19937 rng(hash(u));
    for (int l = 0; l < spec_.lodCount; ++l) {
      int n = spec_.tileBricks(l);
      TileLod lod;
      lod.emptyDistance.resize(std::size_t(n) * n * n);
      for (auto& e : lod.emptyDistance) e = std::uint8_t(1 + rng() % 3);
      std::set<std::tuple<int, int, int>> used;
      int count = 1 + int(rng() % std::max(1, n * n));
      for (int i = 0; i < count; ++i) {
        glm::ivec3 local(rng() % n, rng() % n, rng() % n);
        if (!used.insert({local.x, local.y, local.z}).second) continue;
        Brick b;
        // Content depends on the unshifted coordinate only, so a shifted world is the same world.
        glm::ivec3 unshifted = u * n + local;
        b.coord = t * n + local;
        for (std::size_t s = 0; s < b.distance.size(); ++s)
          b.distance[s] = std::uint16_t((unshifted.x * 131 + unshifted.y * 17 + unshifted.z * 7 + int(s) + l) & 0x3bff);
        b.albedo.fill(std::uint32_t(hash(unshifted) + l));
        b.emission.fill(std::uint32_t(l));
        lod.emptyDistance[std::size_t(local.x + n * (local.y + n * local.z))] = 0;
        lod.bricks.push_back(b);
      }
      std::sort(lod.bricks.begin(), lod.bricks.end(),
                [](const Brick& a, const Brick& b) { return brickCoordLess(a.coord, b.coord); });
      tile->lods.push_back(std::move(lod));
    }
    return tile;
  }

  // Blocks load() until open() is called (proves the frame never waits on I/O).
  void closeGate() {
    std::lock_guard lock(gateMutex_);
    gateOpen_ = false;
  }
  void openGate() {
    {
      std::lock_guard lock(gateMutex_);
      gateOpen_ = true;
    }
    gateCv_.notify_all();
  }

  std::set<std::tuple<int, int, int>> failing;  // tiles whose load() throws
  mutable std::atomic<int> loads{0};
  int latencyMs = 0;  // injected I/O latency per load

 private:
  static std::uint32_t hash(glm::ivec3 c) {
    std::uint32_t h = std::uint32_t(c.x) * 73856093u ^ std::uint32_t(c.y) * 19349663u ^
                      std::uint32_t(c.z) * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    return h ^ (h >> 15);
  }
  void gate() const {
    std::unique_lock lock(gateMutex_);
    gateCv_.wait(lock, [&] { return gateOpen_; });
  }

  PartitionSpec spec_;
  int range_;
  glm::ivec3 shift_;
  mutable std::mutex gateMutex_;
  mutable std::condition_variable gateCv_;
  bool gateOpen_ = true;
};

}  // namespace sdfstream::test
