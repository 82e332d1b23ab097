// Where the generated world's settlements go (world/generate_world.h): a showcase along the
// demo's flight (a forest, a village street with street lamps and parked cars, a hall to fly
// through), further villages joined to a main road, forests, and the route the camera flies.
// Pure planning on the heightfield: boxes (world/box_architecture.h) and named asset placements,
// which generate_world turns into a layout. Deterministic for a seed (core/split_mix_rng.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "world/box_architecture.h"
#include "world/heightfield_source.h"

namespace sdfstream {

// The asset families a plan asks for; generate_world maps each to packaged models.
enum class PlanAsset { Conifer, Broadleaf, Bush, Car, Truck, Container, Forklift };
constexpr int kPlanAssetCount = 7;

struct PlannedAsset {
  PlanAsset kind;
  glm::dvec2 at{0.0};     // world x, z; rests on the ground
  double size = 1.0;      // largest extent, metres
  double yaw = 0.0;       // radians about +Y
  double floor = -1e300;  // stands on max(ground, floor): the hall's floor for things inside it
};

struct WorldPlan {
  std::vector<LayoutBox> boxes;
  std::vector<PlannedAsset> assets;
  std::vector<glm::dvec3> flight;       // the showcase route, world metres, at least 2 points
  glm::dvec2 showcase{0.0};             // the showcase village's street centre
  glm::dvec2 hallLo{0.0}, hallHi{0.0};  // the hall's outer walls (x, z)
  double hallFloor = 0.0, hallCeiling = 0.0;
  int villages = 0, houses = 0, lamps = 0;
  // Rectangles (x, z) the plan occupies; scattered extras keep out of them.
  std::vector<glm::dvec4> occupied;  // (x0, z0, x1, z1)
};

// Plans the settlements on a world `size` metres square centred on the origin.
WorldPlan planWorld(const Heightfield& field, double size, std::uint64_t seed);

// Whether (x, z) lies inside one of the plan's occupied rectangles, grown by `margin` metres.
bool occupiedAt(const WorldPlan& plan, glm::dvec2 at, double margin);

}  // namespace sdfstream
