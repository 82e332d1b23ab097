// One number printed for a report's tables (printf format, e.g. "%.3f"): shared by the
// benchmarks' Markdown and CSV writers.
#pragma once

#include <cstdio>
#include <string>

namespace sdfstream::bench {

inline std::string format(const char* fmt, double v) {
  char text[64];
  std::snprintf(text, sizeof text, fmt, v);
  return text;
}

}  // namespace sdfstream::bench
