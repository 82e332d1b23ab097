#include "demo/moving_objects.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <numbers>

#include <glm/gtc/packing.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/split_mix_rng.h"
#include "world/partition.h"

namespace sdfstream {
namespace {

glm::quat yaw(double radians) { return glm::angleAxis(float(radians), glm::vec3(0, 1, 0)); }

int floorDiv(int a, int b) { return a >= 0 ? a / b : -((b - 1 - a) / b); }

// Height (LOD-0 samples above the origin) of the topmost surface on sample line (lx, lz) of bricks
// sorted highest first: the topmost sample whose distance is <= 0, interpolated with the one
// above it; NaN when none is. A brick not adjacent to the one above starts after empty space (no
// brick: farther than the narrow band from any surface).
float topSurface(const std::vector<const Brick*>& bricks, int lx, int lz) {
  bool haveAbove = false;
  float dAbove = 0.0f;
  int yAbove = 0;
  for (const Brick* b : bricks) {
    for (int sy = 8; sy >= 0; --sy) {
      const int y = 8 * b->coord.y + sy;
      if (haveAbove && y == yAbove) continue;  // the sample the brick above shares
      const float d = glm::unpackHalf1x16(b->distance[brickSampleIndex(lx, sy, lz)]);
      if (d <= 0.0f) {
        float sample = float(y);
        if (haveAbove && yAbove == y + 1 && dAbove > 0.0f) sample += -d / (dAbove - d);
        return sample;
      }
      haveAbove = true;
      dAbove = d;
      yAbove = y;
    }
  }
  return std::numeric_limits<float>::quiet_NaN();
}

}  // namespace

PackGround::PackGround(const TileStore& store, double yMin, double yMax)
    : store_(store),
      tileYMin_(tileOf(store.spec(), glm::dvec3(0.0, yMin, 0.0)).y),
      tileYMax_(tileOf(store.spec(), glm::dvec3(0.0, yMax, 0.0)).y) {}

const std::vector<float>& PackGround::column(glm::ivec2 tile) {
  const auto key = std::make_pair(tile.x, tile.y);
  if (auto it = columns_.find(key); it != columns_.end()) return it->second;
  const int n = store_.spec().tileVoxels;
  std::vector<float>& heights = columns_[key];
  heights.assign(std::size_t(n) * n, std::numeric_limits<float>::quiet_NaN());
  // The column's tiles, top down, only while their heights are taken.
  std::vector<std::shared_ptr<const Tile>> tiles;
  std::map<std::pair<int, int>, std::vector<const Brick*>> bricks;  // by (brick x, brick z)
  for (int ty = tileYMax_; ty >= tileYMin_; --ty) {
    const glm::ivec3 t(tile.x, ty, tile.y);
    if (!store_.hasTile(t)) continue;
    try {
      std::size_t bytes = 0;
      tiles.push_back(store_.load(t, 0, &bytes));
    } catch (const std::exception&) {
      continue;  // a damaged tile: no ground known there (the fly reports failed tiles itself)
    }
    for (const Brick& b : tiles.back()->lods.at(0).bricks)
      bricks[{b.coord.x, b.coord.z}].push_back(&b);
  }
  for (auto& [xz, list] : bricks) {
    std::sort(list.begin(), list.end(),
              [](const Brick* a, const Brick* b) { return a->coord.y > b->coord.y; });
    for (int lz = 0; lz < 8; ++lz)
      for (int lx = 0; lx < 8; ++lx) {
        const int x = 8 * xz.first + lx - tile.x * n, z = 8 * xz.second + lz - tile.y * n;
        if (x >= 0 && z >= 0 && x < n && z < n)
          heights[std::size_t(x) + std::size_t(n) * z] = topSurface(list, lx, lz);
      }
  }
  return heights;
}

std::optional<double> PackGround::heightAt(double x, double z) {
  const PartitionSpec& spec = store_.spec();
  // The LOD-0 sample line nearest to (x, z), and the tile column holding its cell.
  const int ix = int(std::lround((x - spec.origin.x) / spec.voxelSize));
  const int iz = int(std::lround((z - spec.origin.z) / spec.voxelSize));
  const int n = spec.tileVoxels;
  const glm::ivec2 tile(floorDiv(ix, n), floorDiv(iz, n));
  const float h = column(tile)[std::size_t(ix - tile.x * n) + std::size_t(n) * (iz - tile.y * n)];
  if (std::isnan(h)) return std::nullopt;
  return spec.origin.y + double(h) * spec.voxelSize;
}

std::unique_ptr<DemoObjects> flyObjects(PackGround& ground, const FlyPath& path,
                                        const FlyObjectsSettings& settings) {
  auto objects = std::make_unique<DemoObjects>(kDemoObjectSdf);
  ObjectLibrary& lib = objects->library;
  // Bright colours that stand out against terrain greens and browns (linear albedo).
  const std::uint32_t boxes[2] = {lib.addBox(glm::vec3(0.5f), {0.85f, 0.35f, 0.06f, 1.0f}),
                                  lib.addBox(glm::vec3(0.5f), {0.8f, 0.8f, 0.78f, 1.0f})};
  const std::uint32_t spheres[2] = {lib.addSphere(0.5f, {0.15f, 0.3f, 0.85f, 1.0f}, 16),
                                    lib.addSphere(0.5f, {0.85f, 0.1f, 0.12f, 1.0f}, 16)};
  SplitMixRng rng{settings.seed};
  const double stretch = std::max(settings.sEnd - settings.sBegin, 0.0);
  for (std::uint32_t i = 0; i < settings.count; ++i) {
    // Draw every number first, so a skipped object does not shift the ones after it.
    const double s = settings.sBegin + stretch * (double(i) + rng.uniform()) / settings.count;
    const double side = (i % 2 ? 1.0 : -1.0) * rng.uniform(2.0, std::max(settings.maxSide, 2.0));
    const bool sphere = rng.next() & 1;
    const std::uint32_t colour = std::uint32_t(rng.next() & 1);
    const bool large =
        settings.largeEvery > 0 && i % settings.largeEvery == settings.largeEvery - 1;
    const double size = large ? rng.uniform(settings.largeMin, settings.largeMax)
                              : rng.uniform(settings.minSize, settings.maxSize);
    glm::vec3 scale{float(size)};
    if (!sphere)
      for (int a = 0; a < 3; ++a) scale[a] = float(size * rng.uniform(0.5, 1.0));
    const double heading = rng.uniform(0.0, 2.0 * std::numbers::pi);
    const double a = rng.uniform(), b = rng.uniform(), c = rng.uniform(), d = rng.uniform();

    glm::dvec3 forward = path.direction(s);
    forward.y = 0.0;
    forward = glm::length(forward) > 1e-9 ? glm::normalize(forward) : glm::dvec3(1, 0, 0);
    const glm::dvec3 across(-forward.z, 0.0, forward.x);
    // Where the ground is unknown (past a small world's edge) the object moves closer to the
    // path, halving its side distance down to the 2 m minimum, before it is skipped.
    glm::dvec3 at = path.position(s) + across * side;
    std::optional<double> floor = ground.heightAt(at.x, at.z);
    for (double nearer = side * 0.5; !floor && std::abs(nearer) >= 2.0; nearer *= 0.5) {
      at = path.position(s) + across * nearer;
      floor = ground.heightAt(at.x, at.z);
    }
    if (!floor) continue;
    const double radius = 0.5 * glm::length(glm::dvec3(scale));  // unit meshes
    const glm::quat rotation = yaw(heading);
    Mover mover;
    switch ((i + i / 6) % 3) {  // (i / 6: the large ones, every 6th by default, vary too)
      case 0: {                 // hovering circle, high enough over the ground of its whole circle
        const double r = 2.0 + 4.0 * a;
        double top = *floor;
        for (int k = 0; k < 4; ++k) {
          const double angle = k * 0.5 * std::numbers::pi;
          if (auto h = ground.heightAt(at.x + r * std::cos(angle), at.z + r * std::sin(angle)))
            top = std::max(top, *h);
        }
        // Large ones hover lower: their indirect shadow is darker the less sky gets under them.
        const double gap = large ? 0.3 + 1.2 * b : 0.5 + 2.5 * b;
        // (Yaw only: half the height is how far the object reaches below its origin.)
        mover = Orbit{glm::dvec3(at.x, top + 0.5 * scale.y + gap, at.z), r, 4.0 + 6.0 * c, d};
        break;
      }
      case 1: {  // drops 8-20 m, rests, again; spinning
        const double rest = *floor + radius;
        const double drop = 8.0 + 12.0 * a;
        const double fall = std::sqrt(2.0 * drop / kGravity);
        mover = Fall{glm::dvec3(at.x, rest + drop, at.z), rest,   fall + 0.5 + 1.5 * b, c,
                     glm::dvec3(0.3, 1.0, 0.2),           0.5 + d};
        break;
      }
      default: {  // a rectangular loop on the ground, resting on its highest corner
        const double hx = 3.0 + 5.0 * a, hz = 3.0 + 5.0 * b;
        const glm::dvec3 corners[4] = {{-hx, 0, -hz}, {hx, 0, -hz}, {hx, 0, hz}, {-hx, 0, hz}};
        double top = *floor;
        for (const glm::dvec3& k : corners)
          if (auto h = ground.heightAt(at.x + k.x, at.z + k.z)) top = std::max(top, *h);
        const double lift = 0.5 * scale.y;  // yaw-only rotation: half the height
        Path p;
        for (const glm::dvec3& k : corners)
          p.points.push_back(glm::dvec3(at.x, top + lift, at.z) + k);
        p.speed = 3.0 + 5.0 * c;
        p.phase = d;
        mover = std::move(p);
      }
    }
    const std::uint32_t mesh = sphere ? spheres[colour] : boxes[colour];
    const InstanceId id = objects->instances.add(mesh, ObjectTransform{at, rotation, scale});
    objects->motion.add(id, std::move(mover), rotation, scale);
  }
  objects->apply(0.0);
  return objects;
}

std::unique_ptr<DemoObjects> demoSceneObjects() {
  auto objects = std::make_unique<DemoObjects>(kDemoObjectSdf);
  ObjectLibrary& lib = objects->library;
  const std::uint32_t sphere = lib.addSphere(0.55f, {0.2f, 0.4f, 0.9f, 1.0f}, 16);
  const std::uint32_t cube = lib.addBox(glm::vec3(0.35f), {0.9f, 0.45f, 0.1f, 1.0f});
  // Saturated red, so the light its sunlit faces bounce (its cards) colours the ground.
  const std::uint32_t crate =
      lib.addBox(glm::vec3(0.45f, 0.35f, 0.3f), {0.85f, 0.08f, 0.08f, 1.0f});
  InstanceSet& set = objects->instances;
  ScriptedMotion& motion = objects->motion;
  // All three in the open front part of the ground slab, in front of the bunny (x = -1.9), the
  // textured box (x = 0.1, z = 1.9) and the engine (x = 1.7): the front view sees them and the
  // ground around them. A 1.1 m sphere circling 0.4 m above the ground, front left.
  motion.add(set.add(sphere, {}), Orbit{glm::dvec3(-1.3, 0.95, 2.65), 0.35, 16.0, 0.1});
  // A cube that drops 1.6 m (0.57 s) onto the ground right of the textured box, rests and drops
  // again every 3 s; it spins about y only, so resting on its half height it touches the ground.
  // At the demo's 30 GI frames per second it lands within the first GI frames and rests.
  motion.add(set.add(cube, {}),
             Fall{glm::dvec3(1.3, 1.95, 2.5), 0.355, 3.0, 0.0, glm::dvec3(0, 1, 0), 0.3});
  // A red crate driving a 1.1 x 1.0 m loop on the ground, right front.
  motion.add(
      set.add(crate, {}),
      Path{{{2.0, 0.35, 1.5}, {3.1, 0.35, 1.5}, {3.1, 0.35, 2.5}, {2.0, 0.35, 2.5}}, 0.25, 0.0});
  objects->apply(0.0);
  return objects;
}

}  // namespace sdfstream
