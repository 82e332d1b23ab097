#include "bench/gpu_clock_warmup.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/stats.h"

namespace sdfstream::bench {

GpuClockWarmup::GpuClockWarmup(GpuStackTracer& tracer, std::vector<gpu_shared::TraceRay> rays,
                               double batchMilliseconds)
    : tracer_(tracer), rays_(std::move(rays)), batchMs_(batchMilliseconds) {}

std::vector<double> GpuClockWarmup::batch(std::uint32_t dispatches) {
  tracer_.trace(rays_, TraceSettings{}, dispatches);
  std::vector<double> ms;
  for (const gpu::PassTiming& t : tracer_.lastTimings())
    if (t.name == "trace_stack") ms.push_back(t.milliseconds);
  return ms;
}

GpuClockWarmup::Result GpuClockWarmup::run(double minSeconds, double maxSeconds, double tolerance) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  Result r;
  if (rays_.empty()) return r;
  // One dispatch first, to size the batches (lavapipe takes ~0.5 s for 2 M rays, a GPU ~1 ms).
  last_ = batch(1);
  r.batches = 1;
  r.firstMs = r.lastMs = median(last_);
  double previous = r.lastMs;
  while (elapsed() < maxSeconds) {
    const double each = std::max(r.lastMs, 1e-3);
    const std::uint32_t dispatches =
        std::uint32_t(std::clamp(std::lround(batchMs_ / each), 1l, 60l));
    last_ = batch(dispatches);
    ++r.batches;
    r.lastMs = median(last_);
    r.settled = previous > 0.0 && std::abs(r.lastMs - previous) <= tolerance * previous;
    previous = r.lastMs;
    if (elapsed() >= minSeconds && (r.settled || r.lastMs == 0.0)) break;
  }
  r.seconds = elapsed();
  return r;
}

}  // namespace sdfstream::bench
