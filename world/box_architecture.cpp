#include "world/box_architecture.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

namespace sdfstream {
namespace {

void push(std::vector<LayoutBox>& out, glm::dvec3 lo, glm::dvec3 hi, glm::vec3 albedo,
          glm::vec3 emission = glm::vec3(0.0f)) {
  out.push_back({glm::min(lo, hi), glm::max(lo, hi), albedo, emission});
}

// Plaster walls and their roofs, linear RGB: cream, ochre, white, salmon, pale green.
constexpr glm::vec3 kWallColours[] = {{0.62f, 0.55f, 0.40f},
                                      {0.55f, 0.38f, 0.14f},
                                      {0.70f, 0.70f, 0.66f},
                                      {0.62f, 0.33f, 0.25f},
                                      {0.40f, 0.50f, 0.36f}};
constexpr glm::vec3 kRoofColours[] = {
    {0.38f, 0.10f, 0.05f}, {0.12f, 0.12f, 0.14f}, {0.30f, 0.14f, 0.08f}};
constexpr glm::vec3 kStone(0.30f, 0.29f, 0.27f);
constexpr glm::vec3 kGlass(0.03f, 0.04f, 0.06f);
constexpr glm::vec3 kDoorWood(0.16f, 0.08f, 0.04f);
constexpr glm::vec3 kAsphalt(0.06f, 0.06f, 0.065f);
constexpr glm::vec3 kIron(0.08f, 0.08f, 0.09f);
constexpr glm::vec3 kWarmLamp(1.0f, 0.72f, 0.40f);
// A road's top above the highest ground under a slab: a voxel's closest surface must be the
// road's, not the terrain's just below it, or a 1 m world shows green roads.
constexpr double kRoadAboveGround = 0.6;

}  // namespace

nlohmann::json boxesJson(const std::vector<LayoutBox>& boxes) {
  nlohmann::json out = nlohmann::json::array();
  for (const LayoutBox& b : boxes) {
    nlohmann::json j = {{"min", {b.min.x, b.min.y, b.min.z}},
                        {"max", {b.max.x, b.max.y, b.max.z}},
                        {"albedo", {b.albedo.r, b.albedo.g, b.albedo.b}}};
    if (b.emission != glm::vec3(0.0f)) j["emission"] = {b.emission.r, b.emission.g, b.emission.b};
    out.push_back(std::move(j));
  }
  return out;
}

Footing footingOf(const Heightfield& field, glm::dvec2 lo, glm::dvec2 hi) {
  const int nx = std::max(2, int(std::ceil((hi.x - lo.x) / 2.0)) + 1);
  const int nz = std::max(2, int(std::ceil((hi.y - lo.y) / 2.0)) + 1);
  Footing f{1e300, -1e300};
  for (int i = 0; i < nx; ++i)
    for (int k = 0; k < nz; ++k) {
      const double h =
          field.heightAt(lo.x + (hi.x - lo.x) * i / (nx - 1), lo.y + (hi.y - lo.y) * k / (nz - 1));
      f.low = std::min(f.low, h);
      f.high = std::max(f.high, h);
    }
  return f;
}

void addHouse(std::vector<LayoutBox>& out, const Heightfield& field, const HouseDesc& h) {
  const glm::dvec2 lo = h.centre - h.size / 2.0, hi = h.centre + h.size / 2.0;
  const Footing f = footingOf(field, lo, hi);
  const double floor = f.high + 0.1, eaves = floor + h.wallHeight;
  const glm::vec3 wall = kWallColours[h.style % 5], roof = kRoofColours[(h.style / 5) % 3];
  // Plinth down into the lowest ground, so a house on a slope has no gap under it.
  push(out, {lo.x, f.low - 1.5, lo.y}, {hi.x, floor, hi.y}, kStone);
  push(out, {lo.x, floor, lo.y}, {hi.x, eaves, hi.y}, wall);

  // The ridge runs along the longer side; "a" is that axis, "b" the other (x = 0, z = 1).
  const int a = h.size.x >= h.size.y ? 0 : 1, b = 1 - a;
  auto at = [&](double ua, double ub) { return a == 0 ? glm::dvec2(ua, ub) : glm::dvec2(ub, ua); };
  // Window panes and a door, 0.3 m proud of both long façades.
  const double along = h.size[a], across = h.size[b];
  const int windows = std::max(1, int(along / 3.5));
  for (int side = -1; side <= 1; side += 2) {
    const double face = h.centre[b] + side * across / 2.0;
    for (int w = 0; w < windows; ++w) {
      const double u = h.centre[a] - along / 2.0 + (w + 0.5) * along / windows;
      const bool door = side == -1 && w == windows / 2;
      const double y0 = door ? floor : floor + 0.45 * h.wallHeight - 0.9;
      const double y1 = door ? floor + 2.4 : y0 + 1.8;
      const glm::dvec2 p = at(u - (door ? 0.7 : 0.8), face),
                       q = at(u + (door ? 0.7 : 0.8), face + side * 0.3);
      push(out, {p.x, y0, p.y}, {q.x, y1, q.y}, door ? kDoorWood : kGlass);
    }
  }
  // A stepped gable roof: four slabs, each narrower across the ridge, overhanging by 0.5 m.
  const double rise = std::max(2.0, 0.45 * across);
  const int steps = 4;
  for (int s = 0; s < steps; ++s) {
    const double half = (across / 2.0 + 0.5) * (1.0 - double(s) / steps);
    const double y0 = eaves + rise * s / steps, y1 = eaves + rise * (s + 1) / steps;
    const glm::dvec2 p = at(h.centre[a] - along / 2.0 - 0.5, h.centre[b] - half);
    const glm::dvec2 q = at(h.centre[a] + along / 2.0 + 0.5, h.centre[b] + half);
    push(out, {p.x, y0, p.y}, {q.x, std::max(y1, y0 + kMinWallMetres), q.y}, roof);
  }
  const glm::dvec2 c = at(h.centre[a] + along / 4.0, h.centre[b] + across / 5.0);
  push(out, {c.x - 0.6, eaves, c.y - 0.6}, {c.x + 0.6, eaves + rise + 1.2, c.y + 0.6}, kStone);
}

void addRoad(std::vector<LayoutBox>& out, const Heightfield& field, glm::dvec2 from, glm::dvec2 to,
             double width) {
  const int axis = std::abs(to.x - from.x) >= std::abs(to.y - from.y) ? 0 : 1;
  const double start = std::min(from[axis], to[axis]), end = std::max(from[axis], to[axis]);
  const double line = from[1 - axis];
  constexpr double kSlab = 6.0;
  for (double u = start; u < end; u += kSlab) {
    const double u1 = std::min(end, u + kSlab);
    glm::dvec2 lo, hi;
    lo[axis] = u;
    hi[axis] = u1;
    lo[1 - axis] = line - width / 2.0;
    hi[1 - axis] = line + width / 2.0;
    const Footing f = footingOf(field, lo, hi);
    push(out, {lo.x, f.low - kMinWallMetres, lo.y}, {hi.x, f.high + kRoadAboveGround, hi.y},
         kAsphalt);
  }
}

void addStreetLamp(std::vector<LayoutBox>& out, const Heightfield& field, glm::dvec2 at,
                   double height, float radiance) {
  const double g = field.heightAt(at.x, at.y);
  const double r = kMinWallMetres / 2.0;
  push(out, {at.x - r, g - 0.5, at.y - r}, {at.x + r, g + height, at.y + r}, kIron);
  push(out, {at.x - 0.5, g + height, at.y - 0.5},
       {at.x + 0.5, g + height + kMinWallMetres, at.y + 0.5}, glm::vec3(0.9f),
       kWarmLamp * radiance);
}

double addHall(std::vector<LayoutBox>& out, const Heightfield& field, const HallDesc& hall) {
  const glm::dvec2 lo = hall.lo, hi = hall.hi;
  const Footing f = footingOf(field, lo, hi);
  const double floor = f.high + 0.2, top = floor + hall.height;
  const double t = 1.2;  // wall thickness
  const glm::vec3 concrete(0.45f, 0.44f, 0.42f), brickRed(0.45f, 0.11f, 0.07f),
      blueGrey(0.22f, 0.30f, 0.45f), roof(0.22f, 0.22f, 0.23f);
  push(out, {lo.x, f.low - 1.5, lo.y}, {hi.x, floor, hi.y}, concrete);  // floor slab
  push(out, {lo.x, top, lo.y}, {hi.x, top + t, hi.y}, roof);

  // The long walls (across z): solid below and above a band of windows, pillars between them.
  const double sill = floor + 0.45 * hall.height, lintel = floor + 0.75 * hall.height;
  for (int side = 0; side < 2; ++side) {
    const double z0 = side == 0 ? lo.y : hi.y - t, z1 = z0 + t;
    const glm::vec3 c = side == 0 ? blueGrey : brickRed;
    push(out, {lo.x, floor, z0}, {hi.x, sill, z1}, c);
    push(out, {lo.x, lintel, z0}, {hi.x, top, z1}, c);
    const int windows = std::max(1, int((hi.x - lo.x) / 9.0));
    const double pitch = (hi.x - lo.x) / windows;
    for (int w = 0; w <= windows; ++w) {
      const double x = lo.x + w * pitch;
      push(out, {std::max(lo.x, x - 1.5), sill, z0}, {std::min(hi.x, x + 1.5), lintel, z1}, c);
    }
  }
  // The end walls (across x), each with a door opening centred on the hall's axis.
  const double mid = (lo.y + hi.y) / 2.0, dw = hall.doorWidth / 2.0;
  for (double x0 : {lo.x, hi.x - t}) {
    push(out, {x0, floor, lo.y + t}, {x0 + t, top, mid - dw}, concrete);
    push(out, {x0, floor, mid + dw}, {x0 + t, top, hi.y - t}, concrete);
    push(out, {x0, floor + hall.doorHeight, mid - dw}, {x0 + t, top, mid + dw}, concrete);
  }
  // Light strips under the roof, along the hall.
  for (double z : {lo.y + (hi.y - lo.y) * 0.25, mid, lo.y + (hi.y - lo.y) * 0.75})
    push(out, {lo.x + 6.0, top - kMinWallMetres, z - 0.8}, {hi.x - 6.0, top, z + 0.8},
         glm::vec3(0.9f), glm::vec3(1.0f, 0.95f, 0.85f) * hall.lampRadiance);
  return floor;
}

}  // namespace sdfstream
