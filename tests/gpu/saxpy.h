// The selftest_saxpy shader's interface and CPU reference, shared by the gpu tests.
// (A test-only shader, so its push block lives here rather than in shaders/shared.)
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "gpu/compute_pipeline.h"

namespace sdfstream::test {

struct SaxpyPush {      // matches `Push` in shaders/selftest_saxpy.comp (std430 push block)
  float a;              // bytes 0..3
  std::uint32_t count;  // bytes 4..7
};
static_assert(sizeof(SaxpyPush) == 8);

inline gpu::PipelineDesc saxpyDesc() {
  return {
      .storageBufferCount = 2, .pushConstantBytes = sizeof(SaxpyPush), .workgroupSize = {64, 1, 1}};
}

inline gpu::ComputePipeline makeSaxpy(gpu::Context& ctx) {
  return gpu::ComputePipeline(ctx, gpu::ShaderId::selftest_saxpy, saxpyDesc());
}

// Fixed-seed inputs in [-100, 100].
inline std::vector<float> randomFloats(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(-100.0f, 100.0f);
  std::vector<float> v(n);
  for (float& f : v) f = dist(rng);
  return v;
}

// Same two roundings as the shader (`precise`, and -ffp-contract=off here): exact match expected.
inline float saxpyReference(float a, float x, float y) {
  const float ax = a * x;
  return ax + y;
}

}  // namespace sdfstream::test
