// Summary statistics of measured samples (GPU pass times, frame times, latencies): one
// definition for every report, so the same samples give the same p50 / p99 everywhere.
// Percentiles are nearest-rank: a reported value is one that was measured.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace sdfstream {

// The sample at rank round(p · (n − 1)) of the sorted samples, p in [0, 1]; 0 when empty.
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, std::size_t(p * double(v.size() - 1) + 0.5))];
}

// percentile(v, 0.5): the upper median for an even count.
inline double median(std::vector<double> v) { return percentile(std::move(v), 0.5); }

// The arithmetic mean; 0 when empty.
inline double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / double(v.size());
}

}  // namespace sdfstream
