// The async tile loader: worker threads read, verify and decode tiles
// off the frame thread; requests carry priorities and can be cancelled; decoded tiles live in an
// LRU RAM cache within a byte budget; failures are retried with exponential backoff and a tile
// that keeps failing is marked failed and reported, never treated as empty space.
//
// Thread safety: all public methods may be called from any thread; the frame thread only ever
// calls the non-blocking ones (acquire, failed, retainOnly, takeStats).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "streaming/tile_store.h"

namespace sdfstream {

struct LoaderOptions {
  int threads = 2;                          // worker threads
  std::size_t cacheBytes = 512ull << 20;    // decoded tiles kept in RAM (LRU)
  int maxAttempts = 4;                      // then the tile is marked failed
  double backoffMilliseconds = 10.0;        // first retry delay; doubles per attempt
};

struct LoaderStats {
  std::uint64_t tilesLoaded = 0;
  std::uint64_t bytesRead = 0;       // on-disk bytes of loaded tiles
  std::uint64_t bytesDecoded = 0;    // in-memory bytes of decoded tiles
  std::uint64_t retries = 0;
  std::uint64_t failures = 0;        // tiles marked failed
  std::uint64_t cancelled = 0;       // queued requests dropped because no longer wanted
  std::vector<double> latenciesMs;   // request → resident in cache, since the last takeStats
  std::size_t cacheBytes = 0;
  std::size_t cachedTiles = 0;
  std::size_t queued = 0;
};

// What the loader loads and caches: one LOD of one tile.
struct TileKey {
  glm::ivec3 coord{0};
  int lod = 0;
  bool operator==(const TileKey&) const = default;
};
struct TileKeyLess {
  bool operator()(const TileKey& a, const TileKey& b) const {
    if (a.lod != b.lod) return a.lod < b.lod;
    if (a.coord.z != b.coord.z) return a.coord.z < b.coord.z;
    if (a.coord.y != b.coord.y) return a.coord.y < b.coord.y;
    return a.coord.x < b.coord.x;
  }
};

struct IVec3Less {
  bool operator()(const glm::ivec3& a, const glm::ivec3& b) const {
    if (a.z != b.z) return a.z < b.z;
    if (a.y != b.y) return a.y < b.y;
    return a.x < b.x;
  }
};

class TileLoader {
 public:
  TileLoader(const TileStore& store, LoaderOptions options = {});
  ~TileLoader();
  TileLoader(const TileLoader&) = delete;
  TileLoader& operator=(const TileLoader&) = delete;

  // Never blocks on I/O: returns the decoded tile if cached (and marks it recently used), else
  // nullptr after making sure a request exists with at most this priority (lower = sooner).
  std::shared_ptr<const Tile> acquire(TileKey key, double priority);
  bool failed(TileKey key) const;
  std::set<TileKey, TileKeyLess> failedTiles() const;
  // Drops queued (not yet started) requests for tiles `wanted` rejects.
  void retainOnly(const std::function<bool(const TileKey&)>& wanted);
  // Counters since construction; latency samples since the previous call.
  LoaderStats takeStats();
  // Blocks until nothing is queued or in flight (tests and benchmarks only).
  void waitIdle();

 private:
  using Clock = std::chrono::steady_clock;
  struct Request {
    double priority;
    int attempts = 0;
    Clock::time_point notBefore;
    Clock::time_point requestedAt;
  };
  struct CacheEntry {
    std::shared_ptr<const Tile> tile;
    std::size_t bytes;
    std::list<TileKey>::iterator lruPosition;
  };

  void workerLoop();
  void insertIntoCache(TileKey key, std::shared_ptr<const Tile> tile);

  const TileStore& store_;
  LoaderOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  bool stopping_ = false;
  std::map<TileKey, Request, TileKeyLess> queued_;
  std::set<TileKey, TileKeyLess> inFlight_;
  std::set<TileKey, TileKeyLess> failed_;
  std::map<TileKey, CacheEntry, TileKeyLess> cache_;
  std::list<TileKey> lru_;  // front = most recently used
  std::size_t cachedBytes_ = 0;
  std::size_t evictedSinceTrim_ = 0;  // see workerLoop: hands freed tile memory back to the OS
  LoaderStats stats_;
  std::vector<std::thread> workers_;
};

// Decoded size of a tile in RAM (what the cache budget counts).
std::size_t decodedTileBytes(const Tile& tile);

}  // namespace sdfstream
