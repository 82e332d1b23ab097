#include "reference/flat_regions.h"

#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <tuple>
#include <vector>

namespace sdfstream::reference {
namespace {

double luminance(const glm::vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

double relativeSpread(const std::vector<double>& values) {
  double sum = 0.0, sumSq = 0.0;
  for (double v : values) sum += v, sumSq += v * v;
  const double n = double(values.size());
  const double mean = sum / n;
  if (!(mean > 0.0)) return 0.0;
  return std::sqrt(std::max(0.0, sumSq / n - mean * mean)) / mean;
}

}  // namespace

FlatSpread flatRegionSpread(std::span<const glm::vec3> position, std::span<const glm::vec3> normal,
                            std::span<const std::size_t> viewStart, std::span<const glm::vec3> gi,
                            std::span<const glm::vec3> reference, double planeTolerance,
                            std::size_t minPoints) {
  if (normal.size() != position.size() || gi.size() != position.size() ||
      reference.size() != position.size() || viewStart.empty() ||
      viewStart.back() != position.size() || !(planeTolerance > 0.0))
    throw std::invalid_argument("flatRegionSpread: spans of different lengths or a bad tolerance");
  // A plane's key: its unit normal in steps of 1/64 (about 1°) and its offset in tolerances.
  using Key = std::tuple<int, int, int, std::int64_t>;
  FlatSpread out;
  double giSum = 0.0, refSum = 0.0;
  for (std::size_t v = 0; v + 1 < viewStart.size(); ++v) {
    std::map<Key, std::vector<std::size_t>> planes;
    for (std::size_t i = viewStart[v]; i < viewStart[v + 1]; ++i) {
      const glm::dvec3 n = glm::normalize(glm::dvec3(normal[i]));
      const double offset = glm::dot(n, glm::dvec3(position[i]));
      planes[{int(std::lround(n.x * 64.0)), int(std::lround(n.y * 64.0)),
              int(std::lround(n.z * 64.0)), std::int64_t(std::llround(offset / planeTolerance))}]
          .push_back(i);
    }
    const std::vector<std::size_t>* largest = nullptr;
    for (const auto& [key, members] : planes)
      if (!largest || members.size() > largest->size()) largest = &members;
    if (!largest || largest->size() < minPoints) continue;
    std::vector<double> g, r;
    for (std::size_t i : *largest) {
      g.push_back(luminance(gi[i]));
      r.push_back(luminance(reference[i]));
    }
    const double w = double(largest->size());
    giSum += relativeSpread(g) * w;
    refSum += relativeSpread(r) * w;
    out.points += largest->size();
    ++out.regions;
  }
  if (out.points > 0) {
    out.gi = giSum / double(out.points);
    out.reference = refSum / double(out.points);
  }
  return out;
}

}  // namespace sdfstream::reference
