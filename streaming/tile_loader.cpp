#include "streaming/tile_loader.h"

#include <algorithm>
#include <cmath>

#include <malloc.h>

namespace sdfstream {

std::size_t decodedTileBytes(const Tile& tile) {
  std::size_t bytes = sizeof(Tile);
  for (const TileLod& lod : tile.lods)
    bytes += lod.bricks.size() * sizeof(Brick) + lod.emptyDistance.size();
  return bytes;
}

TileLoader::TileLoader(const TileStore& store, LoaderOptions options)
    : store_(store), options_(options) {
  for (int i = 0; i < std::max(1, options_.threads); ++i)
    workers_.emplace_back([this] { workerLoop(); });
}

TileLoader::~TileLoader() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& w : workers_) w.join();
}

std::shared_ptr<const Tile> TileLoader::acquire(TileKey tile, double priority) {
  std::lock_guard lock(mutex_);
  if (auto it = cache_.find(tile); it != cache_.end()) {
    lru_.splice(lru_.begin(), lru_, it->second.lruPosition);
    return it->second.tile;
  }
  if (failed_.count(tile) || inFlight_.count(tile)) return nullptr;
  auto [it, inserted] = queued_.try_emplace(tile);
  if (inserted) {
    it->second.priority = priority;
    it->second.notBefore = it->second.requestedAt = Clock::now();
    wake_.notify_one();
  } else {
    it->second.priority = std::min(it->second.priority, priority);
  }
  return nullptr;
}

bool TileLoader::failed(TileKey tile) const {
  std::lock_guard lock(mutex_);
  return failed_.count(tile) != 0;
}

std::set<TileKey, TileKeyLess> TileLoader::failedTiles() const {
  std::lock_guard lock(mutex_);
  return failed_;
}

void TileLoader::retainOnly(const std::function<bool(const TileKey&)>& wanted) {
  std::lock_guard lock(mutex_);
  for (auto it = queued_.begin(); it != queued_.end();) {
    if (!wanted(it->first)) {
      it = queued_.erase(it);
      ++stats_.cancelled;
    } else {
      ++it;
    }
  }
  if (queued_.empty() && inFlight_.empty()) idle_.notify_all();
}

LoaderStats TileLoader::takeStats() {
  std::lock_guard lock(mutex_);
  LoaderStats s = stats_;
  stats_.latenciesMs.clear();
  s.cacheBytes = cachedBytes_;
  s.cachedTiles = cache_.size();
  s.queued = queued_.size();
  return s;
}

void TileLoader::waitIdle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [&] { return queued_.empty() && inFlight_.empty(); });
}

void TileLoader::insertIntoCache(TileKey key, std::shared_ptr<const Tile> tile) {
  std::size_t bytes = decodedTileBytes(*tile);
  lru_.push_front(key);
  cache_[key] = CacheEntry{std::move(tile), bytes, lru_.begin()};
  cachedBytes_ += bytes;
  // Evict least recently used tiles beyond the budget; holders of a shared_ptr keep theirs alive,
  // so eviction never frees data a caller is still copying from. The newest tile always stays.
  while (cachedBytes_ > options_.cacheBytes && lru_.size() > 1) {
    TileKey victim = lru_.back();
    lru_.pop_back();
    auto it = cache_.find(victim);
    cachedBytes_ -= it->second.bytes;
    evictedSinceTrim_ += it->second.bytes;
    cache_.erase(it);
  }
}

void TileLoader::workerLoop() {
  std::unique_lock lock(mutex_);
  while (true) {
    // The most urgent request whose backoff has expired.
    auto now = Clock::now();
    auto best = queued_.end();
    Clock::time_point earliest = Clock::time_point::max();
    for (auto it = queued_.begin(); it != queued_.end(); ++it) {
      if (it->second.notBefore > now) {
        earliest = std::min(earliest, it->second.notBefore);
        continue;
      }
      if (best == queued_.end() || it->second.priority < best->second.priority) best = it;
    }
    if (stopping_) return;
    if (best == queued_.end()) {
      if (earliest == Clock::time_point::max())
        wake_.wait(lock);
      else
        wake_.wait_until(lock, earliest);
      continue;
    }
    TileKey key = best->first;
    Request request = best->second;
    queued_.erase(best);
    inFlight_.insert(key);
    lock.unlock();

    std::shared_ptr<const Tile> tile;
    std::size_t diskBytes = 0;
    try {
      tile = store_.load(key.coord, key.lod, &diskBytes);
    } catch (const std::exception&) {
      tile = nullptr;
    }

    lock.lock();
    inFlight_.erase(key);
    if (tile) {
      ++stats_.tilesLoaded;
      stats_.bytesRead += diskBytes;
      stats_.bytesDecoded += decodedTileBytes(*tile);
      stats_.latenciesMs.push_back(
          std::chrono::duration<double, std::milli>(Clock::now() - request.requestedAt).count());
      insertIntoCache(key, std::move(tile));
    } else if (++request.attempts >= options_.maxAttempts) {
      failed_.insert(key);
      ++stats_.failures;
    } else {
      ++stats_.retries;
      request.notBefore =
          Clock::now() + std::chrono::microseconds(std::int64_t(
                             1000.0 * options_.backoffMilliseconds * std::pow(2.0, request.attempts - 1)));
      queued_.emplace(key, request);
    }
    if (queued_.empty() && inFlight_.empty()) idle_.notify_all();
    // Decoded tiles are freed on whichever thread drops the last reference, and glibc keeps that
    // memory in per-thread arenas: a 10,000-frame fly-over grew RSS ~20% with a flat heap. Trim
    // once per 64 MiB evicted so RSS follows the cache budget (bench stream measures this).
    if (evictedSinceTrim_ >= (64u << 20)) {
      evictedSinceTrim_ = 0;
      lock.unlock();
      malloc_trim(0);
      lock.lock();
    }
  }
}

}  // namespace sdfstream
