// Brings the GPU's clocks up before a benchmark times a pass. A GPU back from idle runs its first
// second or so of work at its lowest clock and drops back within about half a second of idle:
// an H100 sampled every 100 ms (nvidia-smi) sat at 345 MHz through a bench run's host work,
// took ~1 s of steady work to reach 1,980 MHz, and a pass timed in between read 5.7x slow (the
// primary traversal 3.49 against 0.62 ms). So the real-GPU table warms up with work of its own
// until two batches in a row take the same time, then times.
#pragma once

#include <cstdint>
#include <vector>

#include "gi/gpu_stack_tracer.h"

namespace sdfstream::bench {

class GpuClockWarmup {
 public:
  // The work: `rays` traced through `tracer` (both outlive this object), as many dispatches back
  // to back in one submission as take about batchMilliseconds on the GPU.
  GpuClockWarmup(GpuStackTracer& tracer, std::vector<gpu_shared::TraceRay> rays,
                 double batchMilliseconds = 100.0);

  struct Result {
    int batches = 0;
    double firstMs = 0.0, lastMs = 0.0;  // median dispatch time of the first and last batch
    double seconds = 0.0;                // wall time spent
    bool settled = false;                // two batches in a row agreed within the tolerance
  };
  // Submits batches until at least minSeconds have passed and two batches in a row agree within
  // `tolerance` (relative, median dispatch time), or maxSeconds. Without timestamps (a device
  // that has none) it only spends minSeconds of work.
  Result run(double minSeconds = 1.5, double maxSeconds = 10.0, double tolerance = 0.03);

  // The last batch's dispatch times (ms), each a timing of the same traversal at the clock run()
  // left the GPU at.
  const std::vector<double>& lastBatch() const { return last_; }

 private:
  std::vector<double> batch(std::uint32_t dispatches);

  GpuStackTracer& tracer_;
  std::vector<gpu_shared::TraceRay> rays_;
  double batchMs_;
  std::vector<double> last_;
};

}  // namespace sdfstream::bench
