#include "demo/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "demo/bitmap_font.h"

namespace sdfstream {
namespace {

constexpr glm::u8vec3 kBlack{0, 0, 0};
constexpr glm::u8vec3 kAxisColor{40, 40, 40};
constexpr glm::u8vec3 kGridColor{225, 225, 225};
constexpr glm::u8vec3 kLegendBorder{160, 160, 160};
constexpr int kTargetTicks = 5;
constexpr double kRangePadding = 0.05;  // keeps extreme points off the axes box

glm::u8vec3 toColor8(glm::vec3 c) {
  c = glm::clamp(c, glm::vec3(0.0f), glm::vec3(1.0f));
  return glm::u8vec3(std::lround(c.r * 255.0f), std::lround(c.g * 255.0f),
                     std::lround(c.b * 255.0f));
}

// A value that can be drawn on an axis: finite, and positive on a log axis. Magnitudes near
// DBL_MAX are refused too, so range arithmetic (hi - lo, padding) cannot overflow to infinity.
bool usable(double v, bool log) {
  return std::isfinite(v) && std::abs(v) < 1e300 && (!log || v > 0.0);
}
double axisSpace(double v, bool log) { return log ? std::log10(v) : v; }
double fromAxisSpace(double v, bool log) { return log ? std::pow(10.0, v) : v; }

// Axis range in axis space (log10 for log axes): the data extent, widened when degenerate and
// padded a little so markers at the extremes stay inside the box.
void axisRange(const Chart& chart, bool isX, bool log, double& lo, double& hi) {
  lo = std::numeric_limits<double>::infinity();
  hi = -lo;
  for (const Series& s : chart.series) {
    std::size_t n = std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      // Only points drawable on both axes count, so a skipped point never stretches the range.
      if (!usable(s.x[i], chart.logX) || !usable(s.y[i], chart.logY)) continue;
      double v = axisSpace(isX ? s.x[i] : s.y[i], log);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (lo > hi) {  // no data: an arbitrary unit range (one decade on log axes)
    lo = 0.0;
    hi = 1.0;
    return;
  }
  if (hi - lo <= 1e-12 * std::max(1.0, std::abs(lo))) {
    double pad = log ? 0.5 : std::max(std::abs(lo) * 0.1, 0.5);
    lo -= pad;
    hi += pad;
    return;
  }
  double pad = (hi - lo) * kRangePadding;
  lo -= pad;
  hi += pad;
}

// Log-axis ticks: whole decades, or 1-2-5 steps when the range spans too few decades for
// decades alone to be informative; plain nice ticks when even those are too sparse.
std::vector<double> logTicks(double loExp, double hiExp) {
  std::vector<double> ticks;
  int first = int(std::ceil(loExp - 1e-9)), last = int(std::floor(hiExp + 1e-9));
  int stride = std::max(1, (last - first + kTargetTicks) / (kTargetTicks + 1));
  for (int e = first; e <= last; e += stride) ticks.push_back(std::pow(10.0, e));
  if (ticks.size() >= 3) return ticks;
  ticks.clear();
  for (int e = first - 1; e <= last; ++e)
    for (double m : {1.0, 2.0, 5.0}) {
      double v = m * std::pow(10.0, e), a = std::log10(v);
      if (a >= loExp - 1e-9 && a <= hiExp + 1e-9) ticks.push_back(v);
    }
  if (ticks.size() >= 3) return ticks;
  return niceTicks(std::pow(10.0, loExp), std::pow(10.0, hiExp), kTargetTicks);
}

std::string cleanExponent(std::string s) {
  // "2.50e+06" -> "2.5e6": shorter labels crowd the axis less.
  auto e = s.find('e');
  if (e == std::string::npos) return s;
  std::string mant = s.substr(0, e), exp = s.substr(e + 1);
  if (mant.find('.') != std::string::npos) {
    while (mant.back() == '0') mant.pop_back();
    if (mant.back() == '.') mant.pop_back();
  }
  bool negative = !exp.empty() && exp[0] == '-';
  if (!exp.empty() && (exp[0] == '+' || exp[0] == '-')) exp.erase(0, 1);
  exp.erase(0, std::min(exp.find_first_not_of('0'), exp.size() - 1));
  return mant + "e" + (negative ? "-" : "") + exp;
}

std::string formatLogTick(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return cleanExponent(buf);
}

class Canvas {
 public:
  explicit Canvas(Image8& image) : image_(image) {}
  void set(int x, int y, glm::u8vec3 c) {
    if (x < clip_.x0 || y < clip_.y0 || x >= clip_.x1 || y >= clip_.y1) return;
    std::uint8_t* px = &image_.rgb[(std::size_t(y) * image_.width + x) * 3];
    px[0] = c.r;
    px[1] = c.g;
    px[2] = c.b;
  }
  void fill(PixelRect r, glm::u8vec3 c) {
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) set(x, y, c);
  }
  void hline(int x0, int x1, int y, glm::u8vec3 c) { fill({x0, y, x1 + 1, y + 1}, c); }
  void vline(int x, int y0, int y1, glm::u8vec3 c) { fill({x, y0, x + 1, y1 + 1}, c); }
  void outline(PixelRect r, glm::u8vec3 c) {
    hline(r.x0, r.x1 - 1, r.y0, c);
    hline(r.x0, r.x1 - 1, r.y1 - 1, c);
    vline(r.x0, r.y0, r.y1 - 1, c);
    vline(r.x1 - 1, r.y0, r.y1 - 1, c);
  }
  // A thick line stamped with a square brush of side `thickness` centred on the path.
  void line(glm::dvec2 a, glm::dvec2 b, int thickness, glm::u8vec3 c) {
    double length = std::max(std::abs(b.x - a.x), std::abs(b.y - a.y));
    if (!std::isfinite(length) || length > 1e6) return;  // callers keep points inside the plot
    int steps = int(std::ceil(length));
    int off = (thickness - 1) / 2;
    for (int i = 0; i <= steps; ++i) {
      glm::dvec2 p = steps ? glm::mix(a, b, double(i) / steps) : a;
      int px = int(std::lround(p.x)) - off, py = int(std::lround(p.y)) - off;
      fill({px, py, px + thickness, py + thickness}, c);
    }
  }
  void disc(glm::dvec2 centre, int radius, glm::u8vec3 c) {
    int cx = int(std::lround(centre.x)), cy = int(std::lround(centre.y));
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx)
        if (dx * dx + dy * dy <= radius * radius + radius) set(cx + dx, cy + dy, c);
  }
  // The clip never reaches outside the image: a degenerate chart's plot rectangle can (found by
  // AddressSanitizer, Plot.DegenerateChartsDoNotCrash).
  void clipTo(PixelRect r) {
    clip_ = {std::max(r.x0, 0), std::max(r.y0, 0), std::min(r.x1, image_.width),
             std::min(r.y1, image_.height)};
  }
  void noClip() { clip_ = {0, 0, image_.width, image_.height}; }

 private:
  Image8& image_;
  PixelRect clip_{0, 0, image_.width, image_.height};
};

int markerRadius(int scale) { return 3 * scale; }
int lineThickness(int scale) { return 2 * scale; }

}  // namespace

std::vector<double> niceTicks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || hi <= lo || target < 1) return {};
  double raw = (hi - lo) / target;
  double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double norm = raw / magnitude;
  double step = (norm < 1.5 ? 1.0 : norm < 3.0 ? 2.0 : norm < 7.0 ? 5.0 : 10.0) * magnitude;
  std::vector<double> ticks;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + step * 1e-9; k += 1.0) {
    double v = k * step;
    ticks.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);  // no "-1.4e-17" for zero
  }
  return ticks;
}

std::string formatTick(double value, double step) {
  char buf[48];
  step = std::abs(step);
  double mag = std::abs(value);
  if (value == 0.0) return "0";
  if (mag >= 1e5 || (mag < 1e-3) || (step > 0 && step < 1e-4)) {
    // Significant digits needed so neighbouring ticks stay distinct.
    int digits = step > 0 ? int(std::floor(std::log10(mag)) - std::floor(std::log10(step))) : 3;
    std::snprintf(buf, sizeof buf, "%.*e", std::clamp(digits, 0, 6), value);
    return cleanExponent(buf);
  }
  int decimals = step > 0 ? std::clamp(int(-std::floor(std::log10(step) + 1e-9)), 0, 6) : 3;
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

double ChartLayout::xToPixel(double x) const {
  double t = (axisSpace(x, logX) - axisSpace(xMin, logX)) /
             (axisSpace(xMax, logX) - axisSpace(xMin, logX));
  return plot.x0 + t * (plot.x1 - 1 - plot.x0);
}

double ChartLayout::yToPixel(double y) const {
  double t = (axisSpace(y, logY) - axisSpace(yMin, logY)) /
             (axisSpace(yMax, logY) - axisSpace(yMin, logY));
  return (plot.y1 - 1) - t * (plot.y1 - 1 - plot.y0);
}

ChartLayout layoutChart(const Chart& chart, int width, int height) {
  ChartLayout L;
  L.logX = chart.logX;
  L.logY = chart.logY;
  // Text doubles on large images so it stays readable when the PNG is viewed scaled down.
  int s = L.textScale = (width >= 1600 || height >= 1000) ? 2 : 1;
  int textH = font::textHeight(s), pad = 10 * s, tick = 5 * s;

  double lo, hi;
  axisRange(chart, true, chart.logX, lo, hi);
  L.xMin = fromAxisSpace(lo, chart.logX);
  L.xMax = fromAxisSpace(hi, chart.logX);
  L.xTicks = chart.logX ? logTicks(lo, hi) : niceTicks(lo, hi, kTargetTicks);
  axisRange(chart, false, chart.logY, lo, hi);
  L.yMin = fromAxisSpace(lo, chart.logY);
  L.yMax = fromAxisSpace(hi, chart.logY);
  L.yTicks = chart.logY ? logTicks(lo, hi) : niceTicks(lo, hi, kTargetTicks);

  auto labels = [](const std::vector<double>& ticks, bool log) {
    std::vector<std::string> out;
    double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 0.0;
    for (double t : ticks) out.push_back(log ? formatLogTick(t) : formatTick(t, step));
    return out;
  };
  L.xTickLabels = labels(L.xTicks, chart.logX);
  L.yTickLabels = labels(L.yTicks, chart.logY);

  int yLabelW = 0;
  for (const auto& l : L.yTickLabels) yLabelW = std::max(yLabelW, font::textWidth(l, s));
  int lastXLabelHalf = L.xTickLabels.empty() ? 0 : font::textWidth(L.xTickLabels.back(), s) / 2;

  int top = pad;
  if (!chart.title.empty()) {
    int titleH = font::textHeight(2 * s);
    L.title = {0, top, 0, top + titleH};  // x filled in once the plot's extent is known
    top += titleH + pad;
  }
  int bottom = height - pad - textH - 4 * s - tick;
  if (!chart.xLabel.empty()) bottom -= textH + 6 * s;
  int left = pad + yLabelW + 4 * s + tick;
  if (!chart.yLabel.empty()) left += textH + 6 * s;

  int right = width - std::max(pad * 2, lastXLabelHalf + pad);
  int nameW = 0;
  bool anyName = false;
  for (const Series& se : chart.series)
    if (!se.name.empty()) {
      anyName = true;
      nameW = std::max(nameW, font::textWidth(se.name, s));
    }
  if (anyName) {
    // The legend sits outside the plot, on the right, so it never hides data.
    int rows = 0;
    for (const Series& se : chart.series) rows += !se.name.empty();
    int legendW = 8 * s + 16 * s + 6 * s + nameW + 8 * s;
    int legendH = 6 * s + rows * (textH + 6 * s);
    right = width - pad - legendW - pad;
    L.legend = {right + pad, top, right + pad + legendW, top + legendH};
  }
  // Tiny images still get a (possibly 1-pixel) plot area rather than a negative one.
  right = std::max(right, left + 1);
  bottom = std::max(bottom, top + 1);
  L.plot = {left, top, right, bottom};
  if (!chart.title.empty()) {
    int w = font::textWidth(chart.title, 2 * s);
    int x0 = std::max(0, (left + right) / 2 - w / 2);
    L.title.x0 = x0;
    L.title.x1 = x0 + w;
  }
  return L;
}

Image8 renderChart(const Chart& chart, int width, int height) {
  width = std::max(width, 1);
  height = std::max(height, 1);
  Image8 image{width, height, std::vector<std::uint8_t>(std::size_t(width) * height * 3, 255)};
  ChartLayout L = layoutChart(chart, width, height);
  Canvas canvas(image);
  int s = L.textScale, textH = font::textHeight(s), tick = 5 * s;
  const PixelRect& P = L.plot;

  // Grid first so data and axes draw over it.
  for (double t : L.xTicks)
    canvas.vline(int(std::lround(L.xToPixel(t))), P.y0, P.y1 - 1, kGridColor);
  for (double t : L.yTicks)
    canvas.hline(P.x0, P.x1 - 1, int(std::lround(L.yToPixel(t))), kGridColor);

  canvas.clipTo(P);
  for (const Series& se : chart.series) {
    glm::u8vec3 c = toColor8(se.color);
    std::size_t n = std::min(se.x.size(), se.y.size());
    bool havePrev = false;
    glm::dvec2 prev{};
    for (std::size_t i = 0; i < n; ++i) {
      if (!usable(se.x[i], chart.logX) || !usable(se.y[i], chart.logY)) {
        havePrev = false;  // a gap: the line does not pretend to know the skipped value
        continue;
      }
      glm::dvec2 p{L.xToPixel(se.x[i]), L.yToPixel(se.y[i])};
      if (se.points)
        canvas.disc(p, markerRadius(s), c);
      else if (havePrev)
        canvas.line(prev, p, lineThickness(s), c);
      else  // a lone sample still shows as a dot of line thickness
        canvas.line(p, p, lineThickness(s), c);
      prev = p;
      havePrev = true;
    }
  }
  canvas.noClip();

  canvas.outline({P.x0 - 1, P.y0 - 1, P.x1 + 1, P.y1 + 1}, kAxisColor);
  for (std::size_t i = 0; i < L.xTicks.size(); ++i) {
    int x = int(std::lround(L.xToPixel(L.xTicks[i])));
    canvas.vline(x, P.y1, P.y1 + tick - 1, kAxisColor);
    int w = font::textWidth(L.xTickLabels[i], s);
    font::drawText(image, x - w / 2, P.y1 + tick + 4 * s, L.xTickLabels[i], kBlack, s);
  }
  for (std::size_t i = 0; i < L.yTicks.size(); ++i) {
    int y = int(std::lround(L.yToPixel(L.yTicks[i])));
    canvas.hline(P.x0 - tick - 1, P.x0 - 2, y, kAxisColor);
    int w = font::textWidth(L.yTickLabels[i], s);
    // Centre on the 7 rows above the baseline so digits line up with the tick mark.
    font::drawText(image, P.x0 - tick - 4 * s - w, y - 7 * s / 2, L.yTickLabels[i], kBlack, s);
  }

  if (!chart.title.empty())
    font::drawText(image, L.title.x0, L.title.y0, chart.title, kBlack, 2 * s);
  if (!chart.xLabel.empty()) {
    int w = font::textWidth(chart.xLabel, s);
    font::drawText(image, (P.x0 + P.x1) / 2 - w / 2, height - 10 * s - textH, chart.xLabel, kBlack,
                   s);
  }
  if (!chart.yLabel.empty()) {
    int h = font::textWidth(chart.yLabel, s);
    font::drawTextUp(image, 10 * s, (P.y0 + P.y1) / 2 - h / 2, chart.yLabel, kBlack, s);
  }

  if (!L.legend.empty()) {
    canvas.fill(L.legend, {255, 255, 255});
    canvas.outline(L.legend, kLegendBorder);
    int y = L.legend.y0 + 6 * s;
    for (const Series& se : chart.series) {
      if (se.name.empty()) continue;
      glm::u8vec3 c = toColor8(se.color);
      int swatchX = L.legend.x0 + 8 * s, midY = y + 7 * s / 2;
      if (se.points)
        canvas.disc({swatchX + 8 * s, midY}, markerRadius(s), c);
      else
        canvas.line({swatchX, midY}, {swatchX + 16 * s - 1, midY}, lineThickness(s), c);
      font::drawText(image, swatchX + 22 * s, y, se.name, kBlack, s);
      y += textH + 6 * s;
    }
  }
  return image;
}

void writeChartPng(const std::filesystem::path& path, const Chart& chart, int width, int height) {
  writePng(path, renderChart(chart, width, height));
}

}  // namespace sdfstream
