// The moving-object instances of a scene: which mesh each one shows and where. Per frame the
// caller moves some, then asks which world regions changed (old and new poses) so GI caches
// around them can be refreshed, uploads the set and calls endFrame().
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "objects/object_library.h"

namespace sdfstream {

// world = T·R·S·object. Translation in world metres (double: worlds are kilometres wide); rotation
// normalised before use; scale per axis (non-uniform allowed; negative mirrors).
struct ObjectTransform {
  glm::dvec3 translation{0.0};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z
  glm::vec3 scale{1.0f};

  // Throws std::invalid_argument when a translation or rotation component is non-finite, the
  // rotation is zero, or a scale component is zero or non-finite.
  void validate() const;
  // T·R·S (validate() first: same exceptions).
  glm::dmat4 matrix() const;
  bool operator==(const ObjectTransform&) const = default;
};

struct WorldBox {
  glm::dvec3 min{0.0}, max{0.0};
};

// World AABB of a mesh's grid box (gridMin .. gridMax) under pose: the exact box of its 8
// transformed corners (so it covers every sample the GPU may read). Throws as matrix().
WorldBox worldBoundsOf(const ObjectSdf& sdf, const ObjectTransform& pose);

using InstanceId = std::uint32_t;  // stable handle; never reused while the set lives

struct Instance {
  InstanceId id = 0;
  std::uint32_t mesh = 0;  // ObjectLibrary index
  ObjectTransform pose;
  bool movedThisFrame = false;  // added or moved since the last endFrame()
};

// Dense array + id → slot table: add, move, remove and lookups are O(1). Memory: the instances
// plus 8 bytes per id ever issued. Not thread-safe.
class InstanceSet {
 public:
  // pose.validate()'s std::invalid_argument on a bad pose. The mesh index is checked later,
  // against the library, by changedBoxes / the GPU upload.
  InstanceId add(std::uint32_t mesh, const ObjectTransform& pose);
  // Unknown (or removed) id: std::out_of_range naming the id; bad pose: std::invalid_argument.
  void move(InstanceId id, const ObjectTransform& pose);
  // Moves ids[k] to poses[k] for every k: the same as move() on each pair in order (a later pair
  // of the same id wins; the change record keeps the frame's start pose and lists instances in
  // order of first change), with the checks and the stores in parallel (TBB): thousands of
  // movers a frame. All or nothing: an unknown id (std::out_of_range) or a bad pose
  // (std::invalid_argument) moves none. Spans of different lengths: std::invalid_argument.
  void move(std::span<const InstanceId> ids, std::span<const ObjectTransform> poses);
  // O(1): the last instance takes the removed one's slot. Unknown id: std::out_of_range.
  void remove(InstanceId id);

  bool contains(InstanceId id) const;
  // nullptr when absent; valid until the next add / remove.
  const Instance* find(InstanceId id) const;
  std::size_t size() const { return instances_.size(); }
  // Dense, in no particular order (removal reorders).
  std::span<const Instance> instances() const { return instances_; }

  // For every instance added, moved or removed since the last endFrame(): the world box of its
  // pose at that endFrame() (if it existed then) and of its current pose (if it still exists),
  // in order of first change. Moving twice in a frame reports only the start and end poses; an
  // instance added and removed in one frame reports nothing. Mesh bounds from lib (an unknown
  // mesh index: std::out_of_range).
  std::vector<WorldBox> changedBoxes(const ObjectLibrary& lib) const;
  // The same with each instance's start and end boxes merged into one (their AABB): half the
  // boxes, each covering the whole change, for consumers that only need to be conservative.
  std::vector<WorldBox> changedBounds(const ObjectLibrary& lib) const;
  // The same into `out` (replaced; its capacity is reused from frame to frame).
  void changedBounds(const ObjectLibrary& lib, std::vector<WorldBox>& out) const;
  // Clears movedThisFrame and the change record.
  void endFrame();

 private:
  static constexpr std::uint32_t kAbsent = UINT32_MAX;
  struct Change {
    InstanceId id;
    std::uint32_t mesh;
    std::optional<ObjectTransform> before;  // pose at the last endFrame()
  };
  std::uint32_t slotOf(InstanceId id) const;  // throws std::out_of_range
  void recordChange(const Instance& instance, bool existedBefore);

  std::vector<Instance> instances_;
  std::vector<std::uint32_t> slot_;  // by id: index into instances_, or kAbsent
  std::vector<Change> changes_;
  std::vector<std::uint32_t> changeOf_;  // by id: index into changes_, or kAbsent (this frame)
  // Batch move scratch: by slot, the pairs moving it (then, with repeats, the last pair); by
  // pair, where its change lands in changes_ (kAbsent: none, the instance already changed).
  std::vector<std::uint32_t> lastMove_;
  std::vector<std::uint32_t> changeAt_;
};

}  // namespace sdfstream
