#include "world/world_plan.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/split_mix_rng.h"

namespace sdfstream {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRoadWidth = 8.0, kPavement = 2.5;
constexpr float kStreetLampRadiance = 20.0f;
constexpr float kHallLampRadiance = 2.5f;

// A street's frame: u runs along the street, v across it; alongX says which world axis u is.
struct StreetFrame {
  glm::dvec2 centre{0.0};
  bool alongX = true;
  glm::dvec2 world(double u, double v) const {
    return centre + (alongX ? glm::dvec2(u, v) : glm::dvec2(v, u));
  }
  glm::dvec2 extent(double su, double sv) const {
    return alongX ? glm::dvec2(su, sv) : glm::dvec2(sv, su);
  }
  // Yaw that turns world +x onto the street's direction (+u).
  double yaw() const { return alongX ? 0.0 : -kPi / 2.0; }
};

void occupy(WorldPlan& plan, glm::dvec2 a, glm::dvec2 b) {
  plan.occupied.push_back(glm::dvec4(glm::min(a, b), glm::max(a, b)));
}

void road(WorldPlan& plan, const Heightfield& field, glm::dvec2 from, glm::dvec2 to) {
  addRoad(plan.boxes, field, from, to, kRoadWidth);
  const glm::dvec2 half(kRoadWidth / 2.0 + 1.0);
  occupy(plan, glm::min(from, to) - half, glm::max(from, to) + half);
}

// Houses in two rows on each side of the street over u in [u0, u1] (the back row behind
// gardens, with gaps), street lamps alternating sides every 22 m, cars parked at the kerb and
// trees in the gardens. A crossing road at u = crossing (NaN: none) keeps its width clear.
void planVillage(WorldPlan& plan, const Heightfield& field, const StreetFrame& s, double u0,
                 double u1, double crossing, SplitMixRng& rng) {
  const double clear = kRoadWidth / 2.0 + 3.0;
  auto crosses = [&](double a, double b) { return a < crossing + clear && b > crossing - clear; };
  for (int side = -1; side <= 1; side += 2)
    for (int row = 0; row < 2; ++row) {
      double u = u0 + rng.uniform(0.0, 4.0);
      for (;;) {
        const double su = rng.uniform(8.0, 13.0), sv = rng.uniform(7.0, 10.0);
        if (u + su > u1) break;
        const double gap = rng.uniform(3.0, 7.0);
        if ((row == 1 && rng.uniform() < 0.3) || crosses(u, u + su)) {
          u += su + gap;
          continue;
        }
        const double v = side * (kRoadWidth / 2.0 + kPavement + sv / 2.0 + row * 18.0);
        HouseDesc h;
        h.centre = s.world(u + su / 2.0, v);
        h.size = s.extent(su, sv);
        h.wallHeight = rng.uniform(4.5, 7.5);
        h.style = int(rng.uniform(0.0, 15.0));
        addHouse(plan.boxes, field, h);
        ++plan.houses;
        if (row == 0 && rng.uniform() < 0.6 && !crosses(u - 3.0, u + su + 3.0))
          plan.assets.push_back({PlanAsset::Broadleaf,
                                 s.world(u + su / 2.0 + rng.uniform(-3.0, 3.0),
                                         side * (kRoadWidth / 2.0 + kPavement + sv + 4.5)),
                                 rng.uniform(7.0, 11.0), rng.uniform(0.0, 2.0 * kPi)});
        u += su + gap;
      }
    }
  for (double u = u0; u <= u1; u += 22.0) {
    const int side = int(std::lround((u - u0) / 22.0)) % 2 ? 1 : -1;
    addStreetLamp(plan.boxes, field, s.world(u, side * (kRoadWidth / 2.0 + 1.0)), 5.0,
                  kStreetLampRadiance);
    ++plan.lamps;
  }
  for (double u = u0 + 5.0; u < u1 - 5.0; u += 9.0)
    if (rng.uniform() < 0.35) {
      const int side = rng.uniform() < 0.5 ? -1 : 1;
      plan.assets.push_back({PlanAsset::Car, s.world(u, side * (kRoadWidth / 2.0 - 1.3)),
                             rng.uniform(4.2, 5.0), s.yaw() + (side < 0 ? 0.0 : kPi)});
    }
  occupy(plan, s.world(u0 - 12.0, -45.0), s.world(u1 + 12.0, 45.0));
  ++plan.villages;
}

// Trees on a jittered grid over a rectangle (x, z), `spacing` metres apart, outside everything
// planned so far: conifers mostly, broadleaf trees and bushes between them.
void planForest(WorldPlan& plan, glm::dvec2 lo, glm::dvec2 hi, double spacing, SplitMixRng& rng,
                std::vector<PlannedAsset>& trees) {
  for (double x = lo.x; x < hi.x; x += spacing)
    for (double z = lo.y; z < hi.y; z += spacing) {
      const glm::dvec2 at(x + rng.uniform(0.0, spacing), z + rng.uniform(0.0, spacing));
      const double pick = rng.uniform();
      const double yaw = rng.uniform(0.0, 2.0 * kPi);
      if (occupiedAt(plan, at, 3.0)) continue;
      if (pick < 0.6)
        trees.push_back({PlanAsset::Conifer, at, rng.uniform(10.0, 18.0), yaw});
      else if (pick < 0.9)
        trees.push_back({PlanAsset::Broadleaf, at, rng.uniform(8.0, 14.0), yaw});
      else
        trees.push_back({PlanAsset::Bush, at, rng.uniform(2.0, 4.0), yaw});
    }
}

// The highest ground within `r` metres of `at` (so a camera above it clears nearby hills).
double groundNear(const Heightfield& field, glm::dvec2 at, double r) {
  return footingOf(field, at - glm::dvec2(r), at + glm::dvec2(r)).high;
}

// The showcase's street centre: the flattest site on a 100 m grid over the world's middle, for
// the stretch from the forest to the hall (u in [-350, 150], |v| <= 60).
glm::dvec2 flattestShowcaseSite(const Heightfield& field, double size) {
  glm::dvec2 best(0.0);
  double bestRange = 1e300;
  const double xr = size / 2.0 - 650.0, zr = size / 2.0 - 350.0;
  for (double x = -xr; x <= xr; x += 100.0)
    for (double z = -zr; z <= zr; z += 100.0) {
      const Footing f = footingOf(field, {x - 350.0, z - 60.0}, {x + 150.0, z + 60.0});
      if (f.high - f.low < bestRange) {
        bestRange = f.high - f.low;
        best = {x, z};
      }
    }
  return best;
}

}  // namespace

bool occupiedAt(const WorldPlan& plan, glm::dvec2 at, double margin) {
  for (const glm::dvec4& r : plan.occupied)
    if (at.x >= r.x - margin && at.x <= r.z + margin && at.y >= r.y - margin &&
        at.y <= r.w + margin)
      return true;
  return false;
}

WorldPlan planWorld(const Heightfield& field, double size, std::uint64_t seed) {
  WorldPlan plan;
  SplitMixRng rng{seed * 0x9E3779B97F4A7C15ull + 7};
  const double edge = size / 2.0 - 20.0;

  // The showcase: the main road across the world along x, a village street on it, and the hall
  // at the street's east end, which the road enters and leaves through the hall's doors.
  const StreetFrame main{flattestShowcaseSite(field, size), true};
  plan.showcase = main.centre;
  const glm::dvec2 hallLo = main.world(62.0, -16.0), hallHi = main.world(114.0, 16.0);
  HallDesc hall;
  hall.lo = hallLo;
  hall.hi = hallHi;
  hall.lampRadiance = kHallLampRadiance;
  plan.hallFloor = addHall(plan.boxes, field, hall);
  plan.hallLo = hallLo;
  plan.hallHi = hallHi;
  plan.hallCeiling = plan.hallFloor + hall.height;
  occupy(plan, hallLo - glm::dvec2(2.0), hallHi + glm::dvec2(2.0));
  road(plan, field, {-edge, main.centre.y}, main.world(62.0, 0.0));
  road(plan, field, main.world(114.0, 0.0), {edge, main.centre.y});
  planVillage(plan, field, main, -85.0, 40.0, std::nan(""), rng);
  // Inside the hall: containers along the red wall, a truck and forklifts along the blue one.
  const double floor = plan.hallFloor;
  plan.assets.push_back({PlanAsset::Container, main.world(76.0, 10.0), 12.0, 0.0, floor});
  plan.assets.push_back({PlanAsset::Container, main.world(98.0, 10.5), 12.0, 0.0, floor});
  plan.assets.push_back({PlanAsset::Truck, main.world(96.0, -10.0), 9.0, kPi, floor});
  plan.assets.push_back({PlanAsset::Forklift, main.world(74.0, -9.0), 3.5, 0.6, floor});
  plan.assets.push_back({PlanAsset::Forklift, main.world(84.0, -11.0), 3.5, 2.2, floor});

  // The route: over the forest, down the street at rooftop height, through the hall's doors at
  // half their height, then up and away over the land. Heights are above the highest ground near
  // each point (so hills never cut the flight), except in the hall, where it is its floor.
  struct Waypoint {
    double u, v, height;
    bool inHall;
  };
  for (const Waypoint& w :
       {Waypoint{-135, -25, 32, false}, Waypoint{-95, -8, 16, false}, Waypoint{-50, 0, 9.0, false},
        Waypoint{10, 0, 8.0, false}, Waypoint{50, 0, 5.5, true}, Waypoint{88, 0, 5.5, true},
        Waypoint{126, 0, 5.5, true}, Waypoint{170, 0, 12, false}, Waypoint{240, 15, 30, false},
        Waypoint{360, 50, 55, false}, Waypoint{560, 110, 80, false}}) {
    const glm::dvec2 p = main.world(w.u, w.v);
    const double base = w.inHall ? floor : groundNear(field, p, 15.0);
    plan.flight.push_back({p.x, base + w.height, p.y});
  }

  // Further villages on the flattest of a few random sites each, joined to the main road.
  const int villages = std::max(1, int(std::lround(size * size * 0.4e-6)));
  for (int v = 0; v < villages; ++v) {
    glm::dvec2 best(0.0);
    double bestRange = 1e300;
    for (int tries = 0; tries < 40; ++tries) {
      const glm::dvec2 at(rng.uniform(-edge + 200.0, edge - 200.0),
                          rng.uniform(-edge + 200.0, edge - 200.0));
      if (occupiedAt(plan, at, 150.0)) continue;
      const Footing f = footingOf(field, at - glm::dvec2(80.0), at + glm::dvec2(80.0));
      if (f.high - f.low < bestRange) {
        bestRange = f.high - f.low;
        best = at;
      }
    }
    if (bestRange == 1e300) continue;
    const StreetFrame s{best, rng.uniform() < 0.5};
    const double half = rng.uniform(35.0, 65.0);
    road(plan, field, s.world(-half - 10.0, 0.0), s.world(half + 10.0, 0.0));
    // The road to the main road runs along z: across a street along x, through its middle.
    road(plan, field, best, {best.x, main.centre.y});
    planVillage(plan, field, s, -half, half, s.alongX ? 0.0 : std::nan(""), rng);
  }

  // Forests: the showcase's, either side of the road before the village, a sparser one beyond
  // the hall, then clusters over the rest of the world.
  std::vector<PlannedAsset> trees;
  // The flight's corridors, clear of trees: the descent to the street and the climb after the
  // hall (the camera is below the treetops there).
  occupy(plan, main.world(-160.0, -40.0), main.world(-85.0, 12.0));
  occupy(plan, main.world(114.0, -30.0), main.world(400.0, 80.0));
  planForest(plan, main.world(-360.0, -170.0), main.world(-100.0, 170.0), 10.0, rng, trees);
  planForest(plan, main.world(130.0, -220.0), main.world(420.0, 220.0), 15.0, rng, trees);
  for (int c = 0; c < 12; ++c) {
    const glm::dvec2 at(rng.uniform(-edge + 150.0, edge - 150.0),
                        rng.uniform(-edge + 150.0, edge - 150.0));
    const double r = rng.uniform(60.0, 140.0);
    planForest(plan, at - glm::dvec2(r), at + glm::dvec2(r), 12.0, rng, trees);
  }
  plan.assets.insert(plan.assets.end(), trees.begin(), trees.end());
  return plan;
}

}  // namespace sdfstream
