// `sdfstream bench gi --diagnose`: where the probe GI loses (or gains) light against the
// reference, measured instead of guessed.
//  - Probe rays against Embree, split by the cascade our traversal ends in: every probe ray of
//    one frame of the default configuration, traced through the stack (GpuStackTracer) and on
//    the source triangles. Per cascade: how often we hit where the triangles let the ray escape
//    (an opening closed: sky turned into surface), hit more than a few voxels early (surfaces
//    standing proud), or escape where the triangles are hit (a leak); and the fraction of rays
//    reaching the sky in both.
//  - The bounces: the reference capped at one surface hit after the receiver (sky and emission
//    seen directly, plus the delta lights at the first hit) against the GI without its
//    multi-bounce feedback (bounceGain 0), which is the same transport; the rest of E/E_ref is
//    then the multi-bounce part.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "bench/bench_gi_peers.h"
#include "shaders/shared/probe_layout.h"

namespace sdfstream::bench {

struct RayAgreement {
  std::size_t rays = 0;
  std::size_t embreeHits = 0;  // rays the triangles block within the bound
  std::size_t closed = 0;      // we hit, the triangles let the ray escape
  std::size_t early = 0;       // both hit, ours more than kEarlyVoxels before Embree's
  std::size_t late = 0;        // both hit, ours more than kEarlyVoxels after Embree's
  std::size_t leaks = 0;       // we escape (or run out of steps), the triangles block it
  std::size_t backfaces = 0;   // we hit a surface whose SDF gradient faces along the ray
  double medianAbsDtVoxels = 0.0, p90AbsDtVoxels = 0.0;  // over rays both hit, LOD-0 voxels
};

struct ProbeRayDiagnosis {
  static constexpr double kEarlyVoxels = 4.0;
  std::vector<RayAgreement> byCascade;  // by the cascade our ray ends in (hit or escape)
  RayAgreement all;
  double skyOurs = 0.0, skyEmbree = 0.0;  // fraction of rays that escape
  // Over rays both hit within kEarlyVoxels: mean linear albedo (luminance) of our hit cell (the
  // atlas) and of the source triangle's material at Embree's hit -- what a bounce reflects.
  double albedoOurs = 0.0, albedoEmbree = 0.0;
  std::size_t albedoRays = 0;
};

// Every ray traced through the stack on the device starting in its own cascade first[i] (one
// dispatch per cascade), results in the rays' order.
std::vector<gpu_shared::TraceHit> traceFromCascades(const PeerInputs& in,
                                                    std::span<const gpu_shared::TraceRay> rays,
                                                    std::span<const std::uint32_t> first);

// Traces `rays` through the stack on the device and with Embree (in.threads CPU threads);
// in.triangles gives the source albedo.
ProbeRayDiagnosis diagnoseProbeRays(const PeerInputs& in, const PeerRays& rays);

// The sun's visibility where the probe rays land, ours against Embree's: at each Embree hit
// (its normal turned towards the ray), a shadow ray towards the sun on the triangles, and one
// through the stack from where the light cache would start it: half a voxel of the finest
// cascade holding the point off the SDF's surface, taken as one voxel off the triangle in cascade
// 0 and two in coarser cascades (an open sheet's half-voxel shell; the coarse min-filter's
// dilation). Unbounded: the sun is beyond the stack.
struct SunAgreement {
  std::size_t facing = 0;  // hits facing the sun
  std::size_t sunlit = 0;  // of those, lit on the triangles
  std::size_t lost = 0;    // lit on the triangles, shadowed through the stack
  std::size_t gained = 0;  // shadowed on the triangles, lit through the stack
};
SunAgreement diagnoseSunVisibility(const PeerInputs& in, const PeerRays& rays,
                                   const CascadeStackImage& img, glm::vec3 toSun);

// The cascade probeFieldIrradiance samples each query from: the finest whose probe grid holds
// it at least half a spacing inside (the coarsest otherwise).
std::vector<std::uint32_t> samplingCascades(std::span<const gpu_shared::ProbeVolume> volumes,
                                            std::span<const gpu_shared::ProbeQuery> queries);

// The diagnosis as markdown (a table per cascade and the sky fractions), for summary.md.
std::string diagnosisMarkdown(const ProbeRayDiagnosis& d, std::size_t cascades);

}  // namespace sdfstream::bench
