// Peers of the probe-ray traversal in `sdfstream bench gi`, all given the same
// ray set -- the probe rays of one frame of the GI -- in the same run:
//   sdfstream   sphere tracing through the streamed cascade stack (trace_stack.comp through
//               GpuStackTracer) on the device in use; time = the pass's GPU timestamps
//   embree      Embree 3 rtcIntersect1 on the source triangles (reference/embree_scene.h)
//   openvdb     OpenVDB's tools::LevelSetRayIntersector (linear search + root refinement)
//   nanovdb     NanoVDB's HDDA + ZeroCrossing (voxel-level crossing, no refinement)
// The two VDB peers read one level set of the same triangles at the same voxel size and lattice
// as the pack's LOD 0 (world/level_set_bricks.h meshLevelSet, the importer's own rules); CPU
// peers run on `threads` TBB threads. Each peer's time is the best of `runs`.
// Hit agreement is measured against Embree (the exact answer on the source triangles): the
// fraction of rays on which hit/miss agree, and the median |Δt| over rays both hit, in LOD-0
// voxels.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/context.h"
#include "reference/embree_scene.h"
#include "shaders/shared/sdf_layout.h"
#include "streaming/cascade_stack.h"
#include "world/triangle_scene.h"

namespace sdfstream::bench {

// One ray set in both frames: cascade-0 voxels for the stack tracer, world metres for the rest.
struct PeerRays {
  std::vector<gpu_shared::TraceRay> stack;   // origin/dir in cascade-0 voxels, tMin 0, tMax
  std::vector<glm::vec3> origin, direction;  // world metres, unit direction
  std::vector<float> tMax;                   // world metres (same bound as stack's tMax)
  std::vector<std::uint32_t> cascade;        // the probe's cascade (its rays start there)
  std::vector<std::uint32_t> probeCell;      // the probe's logical grid index in its cascade
};

struct PeerResult {
  std::string name, where;    // "embree", "CPU, 2 threads"
  double milliseconds = 0.0;  // best of runs
  double mraysPerSecond = 0.0;
  std::size_t hits = 0;
  double agreement = 1.0;        // hit/miss agreement with Embree (1 for Embree itself)
  double medianAbsDtVoxels = 0;  // over rays both hit, LOD-0 voxels (0 for Embree)
  double p90AbsDtVoxels = 0;
};

struct PeerInputs {
  gpu::Context* context = nullptr;  // null: the SDF peer is skipped
  const CascadeStack* stack = nullptr;
  std::span<const std::uint32_t> allSlots;
  const TriangleScene* triangles = nullptr;
  const EmbreeScene* embree = nullptr;
  double voxelSize = 0.0;  // LOD 0, metres
  std::uint32_t maxSteps = 256;
  float hitEpsilon = 0.02f;
  int threads = 2;
  int runs = 3;
};

// Runs every peer on the rays. Prints one line per peer as it goes.
std::vector<PeerResult> runPeers(const PeerInputs& in, const PeerRays& rays);

}  // namespace sdfstream::bench
