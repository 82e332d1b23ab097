#include "gi/ray_batch.h"

#include <cstring>

namespace sdfstream {

void RayBatch::stage(std::span<const gpu_shared::TraceRay> rays) {
  count_ = std::uint32_t(rays.size());
  rays_.reserve(rays.size_bytes());
  hits_.reserve(rays.size() * sizeof(gpu_shared::TraceHit));
  if (!rays.empty()) std::memcpy(rays_.host(), rays.data(), rays.size_bytes());
}

void RayBatch::recordUpload(gpu::CommandBatch& batch) {
  rays_.recordCopy(batch, std::size_t(count_) * sizeof(gpu_shared::TraceRay));
}

void RayBatch::recordReadback(gpu::CommandBatch& batch) {
  hits_.recordCopy(batch, std::size_t(count_) * sizeof(gpu_shared::TraceHit));
}

std::vector<gpu_shared::TraceHit> RayBatch::readHits() const {
  std::vector<gpu_shared::TraceHit> hits(count_);
  if (count_) std::memcpy(hits.data(), hits_.host(), hits.size() * sizeof(gpu_shared::TraceHit));
  return hits;
}

}  // namespace sdfstream
