// Sampling the probe field at reduced resolution (one pixel of each blockSize × blockSize block:
// 2 is half resolution, 4 quarter resolution), on the CPU: the sampling pass's order over the
// low-resolution pixels and the upsample, compiled from the GLSL the GPU runs
// (shaders/probe_upsample.glsl). ProbeField::sampleHalfResolution is the GPU side;
// ProbeFieldCpu::sampleHalfResolution puts these together with the CPU's sampling.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "shaders/shared/probe_layout.h"

namespace sdfstream::probe {

// Invocations the reduced-resolution sampling pass runs for a low-resolution image: whole 8×8
// tiles.
std::uint32_t halfResolutionInvocations(std::uint32_t lowWidth, std::uint32_t lowHeight);

// What the reduced-resolution sampling pass samples, invocation by invocation: the query of each
// low-resolution pixel's sampled pixel (a zero normal for invocations past the image's edge or
// blocks without a surface, which sample nothing), where its result goes (low-resolution pixel
// index, or ~0 past the edge) and the sampled pixel's index i + blockSize j in its block
// (blockSize²: none).
struct HalfResolutionPlan {
  std::uint32_t blockSize = 2, lowWidth = 0, lowHeight = 0;
  std::vector<gpu_shared::ProbeQuery> queries;
  std::vector<std::uint32_t> lowPixel, sampledPixel;
};
HalfResolutionPlan planHalfResolution(std::span<const gpu_shared::ProbeQuery> image,
                                      std::uint32_t width, std::uint32_t height,
                                      std::uint32_t blockSize = 2);

// The low-resolution image the pass writes (vec4(irradiance, sampled pixel) or w = -1), from
// the irradiance sampled at the plan's queries.
std::vector<glm::vec4> halfResolutionSamples(const HalfResolutionPlan& plan,
                                             std::span<const glm::vec3> sampled);

// Every full-resolution pixel's irradiance from the low-resolution samples (probe_upsample.comp).
std::vector<glm::vec3> upsampleHalfResolution(std::span<const gpu_shared::ProbeQuery> image,
                                              std::span<const glm::vec4> low, std::uint32_t width,
                                              std::uint32_t height, std::uint32_t blockSize = 2);

// How much a sample at (pk, nk) may stand for a receiver at (p, n) (probeUpsampleSimilarity).
float upsampleSimilarity(glm::vec3 p, glm::vec3 n, glm::vec3 pk, glm::vec3 nk);

}  // namespace sdfstream::probe
