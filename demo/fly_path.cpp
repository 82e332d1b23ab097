#include "demo/fly_path.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace sdfstream {
namespace {
constexpr int kSamplesPerSegment = 64;

// Uniform Catmull-Rom through p1..p2 with neighbours p0, p3 (endpoints duplicated).
glm::dvec3 catmullRom(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2,
                      const glm::dvec3& p3, double t) {
  double t2 = t * t, t3 = t2 * t;
  return 0.5 * ((2.0 * p1) + (-p0 + p2) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2 +
                (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * t3);
}

glm::dvec3 splineAt(const std::vector<glm::dvec3>& w, double u) {  // u in [0, segments]
  int segments = int(w.size()) - 1;
  int i = std::clamp(int(u), 0, segments - 1);
  double t = u - i;
  auto at = [&](int k) { return w[std::clamp(k, 0, int(w.size()) - 1)]; };
  return catmullRom(at(i - 1), at(i), at(i + 1), at(i + 2), t);
}

// Arc-length table: (s, u) pairs.
std::vector<std::pair<double, double>> arcTable(const std::vector<glm::dvec3>& w) {
  std::vector<std::pair<double, double>> table{{0.0, 0.0}};
  int segments = int(w.size()) - 1;
  glm::dvec3 prev = w.front();
  double s = 0.0;
  for (int k = 1; k <= segments * kSamplesPerSegment; ++k) {
    double u = double(k) / kSamplesPerSegment;
    glm::dvec3 p = splineAt(w, u);
    s += glm::length(p - prev);
    prev = p;
    table.push_back({s, u});
  }
  return table;
}

double uAt(const std::vector<glm::dvec3>& w, double s) {
  auto table = arcTable(w);
  s = std::clamp(s, 0.0, table.back().first);
  auto it = std::lower_bound(table.begin(), table.end(), s,
                             [](const auto& e, double v) { return e.first < v; });
  if (it == table.begin()) return 0.0;
  auto prev = it - 1;
  double span = it->first - prev->first;
  double f = span > 0 ? (s - prev->first) / span : 0.0;
  return prev->second + f * (it->second - prev->second);
}
}  // namespace

double FlyPath::length() const { return arcTable(waypoints).back().first; }

glm::dvec3 FlyPath::position(double s) const { return splineAt(waypoints, uAt(waypoints, s)); }

glm::dvec3 FlyPath::direction(double s) const {
  double u = uAt(waypoints, s);
  double du = 1e-3;
  glm::dvec3 d = splineAt(waypoints, std::min(u + du, double(waypoints.size() - 1))) -
                 splineAt(waypoints, std::max(u - du, 0.0));
  double len = glm::length(d);
  return len > 0 ? d / len : glm::dvec3(1, 0, 0);
}

FlyPath readFlyPath(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(InputErrorKind::Io, file.string(), "cannot open path file");
  FlyPath path;
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream ls(line);
    glm::dvec3 p;
    if (!(ls >> p.x)) continue;  // blank line
    if (!(ls >> p.y >> p.z) || !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
      throw InputError(InputErrorKind::Malformed, file.string(),
                       "line " + std::to_string(lineNo) + ": expected three finite numbers x y z");
    path.waypoints.push_back(p);
  }
  if (path.waypoints.size() < 2)
    throw InputError(InputErrorKind::Empty, file.string(), "a path needs at least 2 waypoints");
  return path;
}

FlyPath defaultFlyPath(const glm::dvec3& lo, const glm::dvec3& hi) {
  glm::dvec3 size = hi - lo;
  bool alongX = size.x >= size.z;
  double y = lo.y + 0.6 * size.y;
  FlyPath path;
  for (int i = 0; i <= 4; ++i) {
    double f = 0.1 + 0.8 * i / 4.0;                  // along the long axis
    double g = 0.5 + 0.25 * ((i % 2) ? 1.0 : -1.0);  // weave across the short axis
    glm::dvec3 p = alongX ? glm::dvec3(lo.x + f * size.x, y, lo.z + g * size.z)
                          : glm::dvec3(lo.x + g * size.x, y, lo.z + f * size.z);
    path.waypoints.push_back(p);
  }
  return path;
}

Camera pathCamera(const FlyPath& path, double s) {
  Camera cam;
  cam.position = path.position(s);
  cam.target =
      cam.position + glm::normalize(path.direction(s) + glm::dvec3(0.0, -0.25, 0.0)) * 10.0;
  cam.fovYDegrees = 60.0;
  return cam;
}

}  // namespace sdfstream
