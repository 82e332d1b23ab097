#include <gtest/gtest.h>

#include <stb/stb_image.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "demo/plot.h"

namespace sdfstream {
namespace {

const glm::vec3 kRed{1, 0, 0}, kGreen{0, 1, 0}, kBlue{0, 0, 1};

glm::u8vec3 pixel(const Image8& img, int x, int y) {
  const std::uint8_t* p = &img.rgb[(std::size_t(y) * img.width + x) * 3];
  return {p[0], p[1], p[2]};
}
bool isPure(glm::u8vec3 c, glm::vec3 want) { return c == glm::u8vec3(want * 255.0f); }
int countNonWhite(const Image8& img, PixelRect r) {
  int n = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) n += pixel(img, x, y) != glm::u8vec3(255);
  return n;
}
int countColor(const Image8& img, glm::vec3 c, PixelRect r) {
  int n = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x) n += isPure(pixel(img, x, y), c);
  return n;
}
// Mean column of pixels of colour c inside r (the centre of a marker).
double meanColumn(const Image8& img, glm::vec3 c, PixelRect r) {
  double sum = 0;
  int n = 0;
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x)
      if (isPure(pixel(img, x, y), c)) sum += x, ++n;
  return n ? sum / n : -1.0;
}

Chart redLineAt50() {
  Chart c;
  c.title = "Residency";
  c.xLabel = "time (s)";
  c.yLabel = "MiB";
  c.series.push_back({"range", {0, 100}, {0, 100}, kBlue, true});
  c.series.push_back({"flat", {0, 25, 50, 75, 100}, {50, 50, 50, 50, 50}, kRed});
  return c;
}

TEST(Plot, HorizontalLineLandsInTheMiddleRowBand) {
  Chart c = redLineAt50();
  Image8 img = renderChart(c);
  ASSERT_EQ(img.width, 900);
  ASSERT_EQ(img.height, 500);
  ChartLayout L = layoutChart(c);
  const PixelRect& P = L.plot;
  ASSERT_GT(P.x1 - P.x0, 500);
  ASSERT_GT(P.y1 - P.y0, 300);
  double midRow = (P.y0 + P.y1 - 1) / 2.0;
  EXPECT_NEAR(L.yToPixel(50), midRow, 0.5);
  // Every column across the inner plot has red only within a couple of pixels of the middle.
  int redColumns = 0;
  for (int x = P.x0 + 60; x < P.x1 - 60; ++x) {
    int lo = P.y1, hi = -1;
    for (int y = P.y0; y < P.y1; ++y)
      if (isPure(pixel(img, x, y), kRed)) lo = std::min(lo, y), hi = std::max(hi, y);
    if (hi < 0) continue;
    ++redColumns;
    EXPECT_GE(lo, midRow - 2) << x;
    EXPECT_LE(hi, midRow + 2) << x;
  }
  EXPECT_EQ(redColumns, P.x1 - P.x0 - 120);
  // No red outside the plot area except the legend swatch.
  Image8 copy = img;
  for (int y = L.legend.y0; y < L.legend.y1; ++y)
    for (int x = L.legend.x0; x < L.legend.x1; ++x)
      copy.rgb[(std::size_t(y) * 900 + x) * 3 + 1] = 7;
  EXPECT_EQ(countColor(copy, kRed, {0, 0, 900, 500}) - countColor(copy, kRed, P), 0);
}

TEST(Plot, TitleLegendLabelsAndTicksAreDrawn) {
  Chart c = redLineAt50();
  Image8 img = renderChart(c);
  ChartLayout L = layoutChart(c);
  ASSERT_FALSE(L.title.empty());
  ASSERT_FALSE(L.legend.empty());
  EXPECT_GT(countNonWhite(img, L.title), 40);
  EXPECT_GE(L.legend.x0, L.plot.x1);                // outside the data
  EXPECT_GT(countColor(img, kRed, L.legend), 10);   // line swatch
  EXPECT_GT(countColor(img, kBlue, L.legend), 10);  // marker swatch
  EXPECT_GT(countNonWhite(img, L.legend), 100);     // plus names and border
  // Tick labels: a few nice values, and ink below and left of the plot.
  EXPECT_GE(L.xTicks.size(), 3u);
  EXPECT_LE(L.xTicks.size(), 8u);
  EXPECT_GE(L.yTicks.size(), 3u);
  EXPECT_EQ(L.yTickLabels.front(), "0");
  EXPECT_GT(countNonWhite(img, {L.plot.x0, L.plot.y1 + 2, L.plot.x1, 500}), 100);
  EXPECT_GT(countNonWhite(img, {0, L.plot.y0, L.plot.x0 - 2, L.plot.y1}), 100);
}

TEST(Plot, NonFiniteValuesAreSkipped) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Chart c;
  c.series.push_back({"", {0, 1, 2, 3, 4}, {0, 1, nan, 3, inf}, kRed, true});
  ChartLayout L = layoutChart(c);
  // The range comes from the finite points only.
  EXPECT_LT(L.yMax, 4.0);
  EXPECT_GT(L.yMax, 3.0);
  Image8 img = renderChart(c);
  // Three markers drawn (x = 0, 1, 3), none at x = 2 or 4.
  for (double x : {0.0, 1.0, 3.0, 2.0, 4.0}) {
    int px = int(std::lround(L.xToPixel(x)));
    PixelRect column{px - 1, L.plot.y0, px + 2, L.plot.y1};
    bool expected = x != 2.0 && x != 4.0;
    EXPECT_EQ(countColor(img, kRed, column) > 0, expected) << x;
  }
  // A polyline breaks at the NaN instead of bridging it.
  c.series[0].points = false;
  c.series[0].y = {0, 1, nan, 3, 3};
  img = renderChart(c);
  L = layoutChart(c);
  int mid = int(std::lround(L.xToPixel(2.0)));
  EXPECT_EQ(countColor(img, kRed, {mid - 2, L.plot.y0, mid + 3, L.plot.y1}), 0);
}

TEST(Plot, LogAxisPlacesDecadesEvenly) {
  Chart c;
  c.logX = true;
  c.logY = true;
  c.series.push_back({"a", {10}, {10}, kRed, true});
  c.series.push_back({"b", {100}, {100}, kGreen, true});
  c.series.push_back({"c", {1000}, {1000}, kBlue, true});
  c.series.push_back({"bad", {-5, 0}, {1, 1}, kRed, true});  // not drawable on a log axis
  Image8 img = renderChart(c);
  ChartLayout L = layoutChart(c);
  double r = meanColumn(img, kRed, L.plot), g = meanColumn(img, kGreen, L.plot),
         b = meanColumn(img, kBlue, L.plot);
  ASSERT_GE(r, 0);
  EXPECT_NEAR(g - r, b - g, 1.0);
  EXPECT_GT(g - r, 100);
  EXPECT_NEAR(L.yToPixel(10) - L.yToPixel(100), L.yToPixel(100) - L.yToPixel(1000), 1e-6);
  EXPECT_EQ(L.xTickLabels, (std::vector<std::string>{"10", "100", "1000"}));
}

TEST(Plot, DegenerateChartsDoNotCrash) {
  Chart empty;
  EXPECT_EQ(renderChart(empty).rgb.size(), 900u * 500 * 3);
  Chart single;
  single.title = "one";
  single.series.push_back({"p", {3}, {7}, kRed});
  single.series.push_back({"none", {}, {}, kGreen});
  single.logY = true;
  Image8 img = renderChart(single);
  ChartLayout L = layoutChart(single);
  EXPECT_LT(L.xMin, 3);
  EXPECT_GT(L.xMax, 3);
  EXPECT_GT(countColor(img, kRed, L.plot), 0);
  renderChart(single, 30, 20);  // smaller than the margins
  renderChart(single, 1, 1);
  Chart mismatched;
  mismatched.series.push_back({"m", {1, 2, 3}, {1}, kRed});
  renderChart(mismatched);
  Chart huge;  // range arithmetic must not overflow into an endless line
  huge.series.push_back({"h", {-1e299, 1e299, 0, 1}, {1e308, -1e308, -1e299, 1e299}, kRed});
  renderChart(huge);
}

TEST(Plot, NiceTicksAndLabels) {
  EXPECT_EQ(niceTicks(0, 1000, 5), (std::vector<double>{0, 200, 400, 600, 800, 1000}));
  auto t = niceTicks(-0.05, 1.05, 5);
  ASSERT_EQ(t.size(), 6u);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(t[i], 0.2 * i, 1e-12);
  EXPECT_EQ(formatTick(250, 250), "250");
  EXPECT_EQ(formatTick(0.5, 0.1), "0.5");
  EXPECT_EQ(formatTick(0.25, 0.05), "0.25");
  EXPECT_EQ(formatTick(2.5e6, 5e5), "2.5e6");
  EXPECT_EQ(formatTick(3e-5, 1e-5), "3e-5");
  EXPECT_EQ(formatTick(0, 1e6), "0");
}

TEST(Plot, WritesAPngThatDecodes) {
  auto dir = std::filesystem::temp_directory_path() / "sdfstream_plot_test";
  std::filesystem::create_directories(dir);
  auto path = dir / "chart.png";
  writeChartPng(path, redLineAt50(), 640, 360);
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(path.string().c_str(), &w, &h, &n, 3);
  ASSERT_NE(data, nullptr) << stbi_failure_reason();
  EXPECT_EQ(w, 640);
  EXPECT_EQ(h, 360);
  Image8 img = renderChart(redLineAt50(), 640, 360);
  EXPECT_TRUE(std::equal(img.rgb.begin(), img.rgb.end(), data));
  stbi_image_free(data);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sdfstream
