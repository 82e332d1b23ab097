// The points where `sdfstream bench gi` compares the GI with its reference: the surface seen
// through each pixel centre of each of a scene's views, with its normal and albedo, and the
// images of albedo/π·E over them that FLIP compares.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bench/bench_gi_report.h"
#include "bench/bench_gi_scenes.h"
#include "gpu/context.h"
#include "reference/embree_scene.h"
#include "reference/path_tracer.h"
#include "streaming/cascade_stack.h"

namespace sdfstream::bench {

// The visible surface points of every view: where the reference and the GI are compared.
struct ViewPoints {
  int width = 0, height = 0;
  std::vector<reference::PinholeCamera> cameras;
  std::vector<std::string> names;
  std::vector<glm::vec3> position, normal, albedo;  // world metres; linear albedo in [0, 1]
  std::vector<int> pixel;                           // index in its view's image
  std::vector<std::size_t> start;                   // first point of each view; + end
  std::vector<glm::vec3> reference;                 // E_ref (NoDirectLights); empty: none
  std::vector<glm::vec3> referenceOneBounce;        // the same, paths capped at one surface hit
                                                    // after the point (--diagnose only)
  std::vector<float> exposure;                      // per view, for the tone map
  std::size_t views() const { return start.size() - 1; }
};

// The points the path tracer's camera rays find on the source triangles, albedo from Embree's
// hit on the same triangle.
ViewPoints visiblePoints(const BenchScene& scene, const reference::PathTracer& tracer,
                         const EmbreeScene& embree, int width, int height);

// The large world has no triangles: its visible points come from our own SDF (timing only),
// traced on the GPU through the settled stack from the scene's stream camera.
ViewPoints sdfVisiblePoints(gpu::Context& ctx, const BenchScene& scene, const CascadeStack& stack,
                            std::span<const std::uint32_t> slots, int width, int height);

// Primary-ray SDF traversal alone (trace_stack.comp, no shading): width × height rays from the
// scene's stream camera (inside every cascade, unlike the reference's views, which may look in
// from outside the stack) along its view direction, 60° vertical field of view: the GPU time of
// the pass once the GPU's clocks are up (bench/gpu_clock_warmup.h; the median of the warm-up's
// last batch of dispatches back to back) and how many rays hit, and
// the steps they took. The real-GPU table reports it as rays per second, the traversal's own
// throughput.
// The stream camera's width × height primary rays in the stack's frame (primaryTraceTiming's).
std::vector<gpu_shared::TraceRay> streamCameraRays(const BenchScene& scene,
                                                   const CascadeStack& stack, int width,
                                                   int height);

PrimaryTraceTiming primaryTraceTiming(gpu::Context& ctx, const BenchScene& scene,
                                      const CascadeStack& stack,
                                      std::span<const std::uint32_t> slots, int width, int height);

// albedo/π·E per pixel of view `k` (black where the view sees the sky); e: one per point.
std::vector<glm::vec3> shadedImage(const ViewPoints& v, std::size_t k,
                                   std::span<const glm::vec3> e);

// ACES at `exposure` (a multiplier), sRGB, 8 bits.
void writeToneMappedPng(const std::filesystem::path& path, const std::vector<glm::vec3>& radiance,
                        int w, int h, float exposure);

}  // namespace sdfstream::bench
