// Deterministic motion for tests, the stress benchmark and the demo: each mover is a pure
// function of time, so a run is reproducible frame by frame and any frame can be replayed alone.
#pragma once

#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "objects/instance_set.h"
#include "objects/object_library.h"

namespace sdfstream {

inline constexpr double kGravity = 9.81;  // m/s², Fall

// Circles centre in its horizontal plane (about +y), counter-clockwise seen from above.
struct Orbit {
  glm::dvec3 centre{0.0};
  double radius = 1.0;   // metres, >= 0
  double period = 10.0;  // seconds per turn, > 0
  double phase = 0.0;    // fraction of a turn done at t = 0
};

// Drops from start under kGravity until the instance origin reaches floorHeight, rests there, and
// starts again from start every `period` seconds (before landing if period is shorter than the
// fall). Spins about spinAxis at spinRate all along. The floor is for the origin: keep it at
// least the object's bounding radius above the ground it should not sink into.
struct Fall {
  glm::dvec3 start{0.0};
  double floorHeight = 0.0;            // world y, <= start.y
  double period = 2.0;                 // seconds, > 0
  double phase = 0.0;                  // fraction of the period done at t = 0
  glm::dvec3 spinAxis{0.0, 1.0, 0.0};  // nonzero
  double spinRate = 0.5;               // radians per second
};

// Follows a closed polyline (the last point joins the first) at constant speed: "traffic". The
// orientation stays the bound rotation.
struct Path {
  std::vector<glm::dvec3> points;  // >= 2, loop length > 0
  double speed = 1.0;              // metres per second (negative runs backwards)
  double phase = 0.0;              // fraction of the loop done at t = 0
};

using Mover = std::variant<Orbit, Fall, Path>;

class ScriptedMotion {
 public:
  // Binds a mover to an instance. rotation and scale complete its pose (Fall spins on top of
  // rotation). Non-finite or out-of-range parameters (see the structs) and bad rotation / scale
  // (ObjectTransform::validate) throw std::invalid_argument. Returns the binding's index.
  std::size_t add(InstanceId id, Mover mover, glm::quat rotation = glm::quat(1, 0, 0, 0),
                  glm::vec3 scale = glm::vec3(1.0f));

  std::size_t size() const { return bindings_.size(); }
  InstanceId instance(std::size_t binding) const { return bindings_.at(binding).id; }
  const Mover& mover(std::size_t binding) const { return bindings_.at(binding).mover; }

  // Pose of a binding at time t (seconds, any finite value): a pure function of t.
  ObjectTransform poseAt(std::size_t binding, double timeSeconds) const;

  // Moves every bound instance still in the set to its pose at t, calling set.move only when
  // that pose differs from its current one (so a still mover does not flag its region as
  // changed). Instances removed from the set are skipped. No exceptions after a valid add.
  // Not to be called concurrently on one ScriptedMotion (it reuses a scratch buffer).
  void apply(InstanceSet& set, double timeSeconds) const;

 private:
  struct Binding {
    InstanceId id;
    Mover mover;
    glm::quat rotation;
    glm::vec3 scale;
    std::vector<double> pathLength;  // Path: length from points[0] to each point, then the loop
  };
  std::vector<Binding> bindings_;
  // apply's scratch: by binding, whether its pose changed (then 1 + its place among the moves,
  // 0 when unchanged) and the pose; then the moves.
  mutable std::vector<std::uint32_t> changed_;
  mutable std::vector<ObjectTransform> poses_;
  mutable std::vector<InstanceId> moveIds_;
  mutable std::vector<ObjectTransform> movePoses_;
};

// Adds `count` instances spread uniformly over `area` (world box) and returns their motion, all
// deterministic from `seed`: unit boxes and unit spheres (0.5 m radius) in about equal numbers,
// scaled per axis to 0.3–2 m (non-uniform), randomly rotated, each bound to an Orbit (radius
// 0.5–3 m), a Fall (to area.min.y plus its bounding radius) or a Path (a rectangular loop of
// 1–8 m half-sizes at 2–12 m/s), chosen at random. Instances start at their pose for t = 0.
// The two meshes are added to lib once, named "spread:box" and "spread:sphere", and reused when
// the library already holds those names. Orbit and Path sizes shrink to a quarter of the area's
// smaller horizontal side (an area flat in x or z gets still movers instead of paths). area must be
// finite with min <= max (std::invalid_argument). Used by the stress benchmark for 10..10,000
// objects. meshes > 2 spreads the instances over that many meshes instead: the box and the
// sphere, then boxes and spheres of other proportions and colours ("spread:box-k",
// "spread:sphere-k"), for measuring what per-mesh data (cards) costs; meshes = 2 draws exactly
// as before.
ScriptedMotion spreadObjects(InstanceSet& set, ObjectLibrary& lib, std::uint32_t count,
                             WorldBox area, std::uint64_t seed, std::uint32_t meshes = 2);

}  // namespace sdfstream
