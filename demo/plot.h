// Tiny dependency-free line/scatter charts written as PNG: benchmarks and fly-through metrics
// (residency and bytes streamed over time, error vs time with a Pareto front) get a picture
// next to their CSV without needing Python or gnuplot on the machine that ran them.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "demo/frame_image.h"

namespace sdfstream {

struct Series {
  std::string name;          // shown in the legend; series with an empty name get no legend entry
  std::vector<double> x, y;  // pairs beyond the shorter of the two are ignored
  glm::vec3 color{0.0f};     // 0..1
  bool points = false;       // markers instead of a polyline
};

struct Chart {
  std::string title, xLabel, yLabel;
  std::vector<Series> series;
  bool logX = false, logY = false;  // values <= 0 cannot be shown on a log axis and are skipped
};

// Half-open pixel rectangle [x0, x1) x [y0, y1); empty when x0 == x1.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

// Where everything lands for one image size. renderChart draws exactly this layout; it is
// public so tests and callers can find the plot area and map data values to pixels.
struct ChartLayout {
  PixelRect plot;    // inside of the axes box; data ranges map onto its first..last pixel
  PixelRect title;   // empty when the chart has no title
  PixelRect legend;  // empty when no series has a name
  double xMin = 0, xMax = 1, yMin = 0, yMax = 1;  // axis ranges in data units
  bool logX = false, logY = false;
  std::vector<double> xTicks, yTicks;  // in data units, ascending
  std::vector<std::string> xTickLabels, yTickLabels;
  int textScale = 1;  // integer scale of tick/axis/legend text (the title is twice this)

  double xToPixel(double x) const;  // pixel column (fractional) of a data x
  double yToPixel(double y) const;  // pixel row (fractional, top = 0) of a data y
};

ChartLayout layoutChart(const Chart& chart, int width = 900, int height = 500);

// White background, grid, axes with ~5 nice ticks, title, axis labels, legend. Non-finite values
// are skipped and break a polyline (a gap shows the missing samples rather than hiding them).
Image8 renderChart(const Chart& chart, int width = 900, int height = 500);

// renderChart + writePng (atomic). Throws InputError(Io) on failure.
void writeChartPng(const std::filesystem::path& path, const Chart& chart, int width = 900,
                   int height = 500);

// About `target` evenly spaced round values (1, 2 or 5 times a power of ten apart) within
// [lo, hi]. Exposed for tests.
std::vector<double> niceTicks(double lo, double hi, int target = 5);
// Tick label: plain decimals with just enough digits for `step`, "2.5e6" style for very large or
// very small magnitudes.
std::string formatTick(double value, double step);

}  // namespace sdfstream
