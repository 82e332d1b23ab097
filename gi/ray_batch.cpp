#include "gi/ray_batch.h"

namespace sdfstream {

void RayBatch::stage(std::span<const gpu_shared::TraceRay> rays) {
  count_ = std::uint32_t(rays.size());
  const std::size_t rayBytes = rays.size_bytes();
  const std::size_t hitBytes = rays.size() * sizeof(gpu_shared::TraceHit);
  if (rays_.size() < rayBytes) rays_ = gpu::Buffer(context_, rayBytes, gpu::BufferKind::Upload);
  if (hits_.size() < hitBytes) hits_ = gpu::Buffer(context_, hitBytes, gpu::BufferKind::Readback);
  rays_.upload(rays.data(), rayBytes);
}

std::vector<gpu_shared::TraceHit> RayBatch::readHits() const {
  std::vector<gpu_shared::TraceHit> hits(count_);
  hits_.download(hits.data(), hits.size() * sizeof(gpu_shared::TraceHit));
  return hits;
}

}  // namespace sdfstream
