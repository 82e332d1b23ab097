// Buildings, roads and street lamps made of axis-aligned boxes, set on a heightfield: the
// architecture of the generated world (world/generate_world.h). A layout's "boxes" are closed and
// carry their own albedo and emission (world/scene_layout.h), so no asset file is needed and a
// building's walls can be as thick as the world's voxels (1 m in the demo world): a wall thinner
// than a voxel would vanish from the SDF, so every wall and slab here is at least
// kMinWallMetres thick.
#pragma once

#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include "world/heightfield_source.h"

namespace sdfstream {

constexpr double kMinWallMetres = 1.0;

struct LayoutBox {
  glm::dvec3 min{0.0}, max{0.0};
  glm::vec3 albedo{0.8f};    // linear
  glm::vec3 emission{0.0f};  // linear radiance
};

// The layout JSON "boxes" array.
nlohmann::json boxesJson(const std::vector<LayoutBox>& boxes);

// Lowest and highest ground over the rectangle [x0, x1] × [z0, z1] (sampled every ~2 m).
struct Footing {
  double low = 0.0, high = 0.0;
};
Footing footingOf(const Heightfield& field, glm::dvec2 lo, glm::dvec2 hi);

// A closed house: a plinth from below the lowest ground to the floor (the highest ground under
// it), walls of `wallHeight`, a stepped gable roof whose ridge runs along the longer side, dark
// window panes on the long façades and a chimney. `style` picks the wall and roof colours.
struct HouseDesc {
  glm::dvec2 centre{0.0};  // world x, z
  glm::dvec2 size{10.0};   // extent along x, z (metres)
  double wallHeight = 6.0;
  int style = 0;
};
void addHouse(std::vector<LayoutBox>& out, const Heightfield& field, const HouseDesc& house);

// A road from `from` to `to` (the two must share x or z: roads run along an axis), `width`
// metres wide, laid as short slabs whose tops follow the ground 0.6 m above it.
void addRoad(std::vector<LayoutBox>& out, const Heightfield& field, glm::dvec2 from, glm::dvec2 to,
             double width);

// A street lamp at `at`: a post and an emissive head at `height` metres (warm white, radiance
// `radiance`).
void addStreetLamp(std::vector<LayoutBox>& out, const Heightfield& field, glm::dvec2 at,
                   double height, float radiance);

// A hall you can fly into: a box of walls, floor slab and roof over [lo, hi] (x, z), `height`
// metres tall inside, with a door opening `doorWidth` × `doorHeight` centred in each of its two
// walls across x, windows high in the two long walls (shafts of sun), coloured long walls (red and
// blue-grey: the light they bounce shows in the indirect layer) and emissive light strips under
// the roof. Returns the inside floor height.
struct HallDesc {
  glm::dvec2 lo{0.0}, hi{0.0};
  double height = 14.0;
  double doorWidth = 12.0, doorHeight = 10.0;
  float lampRadiance = 6.0f;
};
double addHall(std::vector<LayoutBox>& out, const Heightfield& field, const HallDesc& hall);

}  // namespace sdfstream
