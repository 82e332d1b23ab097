// Camera-centred scrolling cascades fed from a world pack (Godot SDFGI slides,
// "cascades" and "scrolling"). Cascade c covers 16³ pages of LOD-c bricks (128³ cells of voxel
// v0·2^c) around the camera; all cascades share one brick atlas with a fixed slot budget.
//
// Per frame, update():
//  - recentres each cascade on the camera (snapped to its bricks); only pages whose brick
//    changed (the entering slab) are invalidated; their atlas slots are released;
//  - fills invalidated pages from decoded tiles already in the loader's RAM cache, finer
//    cascades and nearer pages first, within a per-frame upload budget;
//  - never waits: a page whose tile is not decoded yet is marked kPageMissing (traversal falls
//    back to a coarser cascade there) and counted; its tile is requested asynchronously.
// The result is the CPU image of the GPU state: page tables (toroidal, cascade-major) and the
// atlas, plus the list of slots whose contents changed (what to upload).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "streaming/cascade.h"
#include "streaming/tile_loader.h"

namespace sdfstream {

// The whole cascade stack as the stack traversal reads it: page tables of every cascade
// (cascade-major), the shared atlas (not copied: the stack keeps it) and per-cascade params.
struct CascadeStackImage {
  std::vector<std::uint32_t> pageTables;  // cascades × 4096
  const std::vector<std::uint32_t>* distanceAtlas = nullptr;
  const std::vector<std::uint32_t>* albedoAtlas = nullptr;
  const std::vector<std::uint32_t>* emissionAtlas = nullptr;
  std::vector<gpu_shared::CascadeTraceParams> params;
  glm::dvec3 cascade0MinWorld{0.0};  // world position of cascade 0's minimum corner
  double voxelSize0 = 0.0;           // cascade-0 voxel size (metres)
  // Window origin of each cascade in its own bricks (world-absolute, so it only changes when the
  // cascade scrolls); the probe grids scroll with it. Empty for hand-built images: all zero.
  std::vector<glm::ivec3> originBricks;

  // Cascade-0-relative voxel coordinates of a world position (what rays are given in).
  glm::vec3 toStack(const glm::dvec3& world) const {
    return glm::vec3((world - cascade0MinWorld) / voxelSize0);
  }
};

struct StreamingOptions {
  int cascades = 6;                             // 1..8
  std::uint32_t atlasSlots = 16384;             // shared brick budget (see atlasBytes())
  std::size_t uploadBytesPerFrame = 16u << 20;  // brick bytes copied into the atlas per frame
};

struct CascadeFrameStats {
  std::uint32_t pagesChanged = 0;   // pages invalidated by this frame's scroll
  std::uint32_t residentBricks = 0;
  std::uint32_t requiredBricks = 0;  // resident + missing pages whose tile holds surface
  std::uint32_t missingPages = 0;    // needed but not resident (tile not decoded / atlas full)
};

struct StreamFrameStats {
  std::vector<CascadeFrameStats> cascades;
  std::uint64_t bytesUploaded = 0;  // brick bytes written into the atlas this frame
  std::uint32_t missingPages = 0;
  std::uint32_t failedPages = 0;    // missing because their tile failed to load
  std::uint32_t atlasFullPages = 0;
  std::uint32_t atlasSlotsUsed = 0;
};

class CascadeStack {
 public:
  CascadeStack(const TileStore& store, TileLoader& loader, StreamingOptions options = {});

  // viewDirection (unit, optional): pages in front of the camera are filled and requested before
  // pages behind it at the same distance.
  StreamFrameStats update(const glm::dvec3& cameraWorld,
                          const glm::dvec3& viewDirection = glm::dvec3(0.0));

  int cascadeCount() const { return int(cascades_.size()); }
  const StreamingOptions& options() const { return options_; }
  // Page table of cascade c: 4096 entries, toroidally addressed (entry of brick b at b mod 16).
  std::span<const std::uint32_t> pageTable(int c) const { return cascades_[c].entries; }
  glm::ivec3 originBrick(int c) const { return cascades_[c].origin; }
  double voxelSize(int c) const;
  // The shared atlas (all slots) and the slots rewritten since the last takeDirtySlots().
  const std::vector<std::uint32_t>& atlasDistance() const { return distance_; }
  const std::vector<std::uint32_t>& atlasAlbedo() const { return albedo_; }
  const std::vector<std::uint32_t>& atlasEmission() const { return emission_; }
  std::vector<std::uint32_t> takeDirtySlots();
  std::size_t atlasBytes() const;
  std::uint32_t atlasSlots() const { return options_.atlasSlots; }
  // Keeps the stack within the first `slots` atlas slots (the device could not hold them all):
  // resident pages in slots beyond are released (they stream in again into slots below, or
  // count as atlasFullPages when none is free). Never grows the budget.
  void limitAtlasSlots(std::uint32_t slots);
  // Every cascade as the stack traversal takes it (copies the page tables, points at the atlas).
  CascadeStackImage stackImage() const;
  // A cascade as the single-cascade tracer takes it (copies the page table and the atlas).
  CascadeImage cascadeImage(int c) const;
  // True when no page of any cascade is missing.
  bool settled() const;

 private:
  struct Cascade {
    glm::ivec3 origin{0};
    bool placed = false;
    std::vector<std::uint32_t> entries;   // 4096, toroidal
    std::vector<glm::ivec3> bricks;       // brick held by each toroidal slot
    std::vector<std::uint8_t> pending;    // 1 = needs filling
    std::uint32_t pendingCount = 0;
  };
  void scroll(int c, glm::ivec3 newOrigin, CascadeFrameStats& stats);
  void releasePage(Cascade& cascade, std::uint32_t page);

  const TileStore& store_;
  TileLoader& loader_;
  StreamingOptions options_;
  std::vector<Cascade> cascades_;
  std::vector<std::uint32_t> distance_, albedo_, emission_;
  std::vector<std::uint32_t> freeSlots_;
  std::vector<std::uint32_t> dirtySlots_;
};

}  // namespace sdfstream
