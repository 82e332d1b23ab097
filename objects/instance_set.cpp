#include "objects/instance_set.h"

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <glm/gtc/matrix_transform.hpp>

namespace sdfstream {
namespace {

bool finite(glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// T·R·S composed directly: R's columns scaled, then the translation (no 4×4 products; this
// runs for every instance every frame). For a pose already validated.
glm::dmat4 matrixOfValid(const ObjectTransform& pose) {
  const glm::dmat3 r = glm::mat3_cast(glm::normalize(
      glm::dquat(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)));
  glm::dmat4 m(1.0);
  for (int c = 0; c < 3; ++c) m[c] = glm::dvec4(r[c] * double(pose.scale[c]), 0.0);
  m[3] = glm::dvec4(pose.translation, 1.0);
  return m;
}

// worldBoundsOf for a pose already validated: the poses of an InstanceSet all are (add and move
// check them), so its changed boxes, two per moving instance a frame, skip the checks.
WorldBox boundsOfValid(const ObjectSdf& sdf, const ObjectTransform& pose) {
  // The AABB of a transformed box: its centre moved, plus |M| (the 3×3 part, absolute values)
  // times its half extents -- the 8 corners' min and max without transforming 8 corners.
  const glm::dmat4 m = matrixOfValid(pose);
  const glm::dvec3 lo(sdf.gridMin), hi(sdf.gridMax());
  const glm::dvec3 centre(m * glm::dvec4(0.5 * (lo + hi), 1.0)), half = 0.5 * (hi - lo);
  glm::dvec3 reach(0.0);
  for (int c = 0; c < 3; ++c) reach += glm::abs(glm::dvec3(m[c])) * half[c];
  return WorldBox{centre - reach, centre + reach};
}

}  // namespace

void ObjectTransform::validate() const {
  if (!finite(translation)) throw std::invalid_argument("ObjectTransform: non-finite translation");
  const glm::dvec4 q(rotation.w, rotation.x, rotation.y, rotation.z);
  if (!finite(glm::dvec3(q)) || !std::isfinite(q.w) || glm::dot(q, q) == 0.0)
    throw std::invalid_argument("ObjectTransform: rotation is zero or non-finite");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(scale[a]) || scale[a] == 0.0f)
      throw std::invalid_argument("ObjectTransform: scale component " + std::to_string(a) + " is " +
                                  std::to_string(scale[a]) + " (must be finite and nonzero)");
}

glm::dmat4 ObjectTransform::matrix() const {
  validate();
  return matrixOfValid(*this);
}

WorldBox worldBoundsOf(const ObjectSdf& sdf, const ObjectTransform& pose) {
  pose.validate();
  return boundsOfValid(sdf, pose);
}

InstanceId InstanceSet::add(std::uint32_t mesh, const ObjectTransform& pose) {
  pose.validate();
  if (slot_.size() >= std::size_t(UINT32_MAX))
    throw std::length_error("InstanceSet: ids exhausted");
  const InstanceId id = InstanceId(slot_.size());
  slot_.push_back(std::uint32_t(instances_.size()));
  changeOf_.push_back(kAbsent);
  instances_.push_back({id, mesh, pose, true});
  recordChange(instances_.back(), false);
  return id;
}

std::uint32_t InstanceSet::slotOf(InstanceId id) const {
  if (id >= slot_.size() || slot_[id] == kAbsent)
    throw std::out_of_range("InstanceSet: no instance with id " + std::to_string(id));
  return slot_[id];
}

void InstanceSet::move(InstanceId id, const ObjectTransform& pose) {
  const std::uint32_t slot = slotOf(id);
  pose.validate();
  Instance& instance = instances_[slot];
  recordChange(instance, true);  // before the pose changes: keeps the frame's start pose
  instance.pose = pose;
  instance.movedThisFrame = true;
}

void InstanceSet::move(std::span<const InstanceId> ids, std::span<const ObjectTransform> poses) {
  if (ids.size() != poses.size())
    throw std::invalid_argument("InstanceSet::move: " + std::to_string(ids.size()) + " ids but " +
                                std::to_string(poses.size()) + " poses");
  if (ids.size() >= std::size_t(UINT32_MAX))
    throw std::length_error("InstanceSet::move: too many pairs in one batch");
  constexpr std::size_t kPairsPerTask = 1024;
  auto each = [&](auto body) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ids.size(), kPairsPerTask),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t k = range.begin(); k != range.end(); ++k) body(k);
                      });
  };
  // Every check before any change, so a throw (the first task's, rethrown) leaves the set as it
  // was.
  each([&](std::size_t k) {
    slotOf(ids[k]);
    poses[k].validate();
  });
  // How many pairs move each slot: a batch without repeated ids (the usual one) records and
  // stores in parallel; with repeats, the record is kept serially.
  lastMove_.resize(instances_.size());
  each([&](std::size_t k) { std::atomic_ref(lastMove_[slot_[ids[k]]]).store(0u); });
  std::atomic<bool> repeated = false;
  each([&](std::size_t k) {
    if (std::atomic_ref(lastMove_[slot_[ids[k]]]).fetch_add(1u) > 0u) repeated = true;
  });
  if (!repeated) {
    // The ordered change record: an instance's first change of the frame appends its start
    // pose, at the place a serial walk of the pairs would (an exclusive scan of the new ones).
    changeAt_.resize(ids.size());
    std::uint32_t appended = std::uint32_t(changes_.size());
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const bool first = changeOf_[ids[k]] == kAbsent;
      changeAt_[k] = first ? appended : kAbsent;
      appended += first ? 1u : 0u;
    }
    changes_.resize(appended);
    each([&](std::size_t k) {
      Instance& instance = instances_[slot_[ids[k]]];
      if (changeAt_[k] != kAbsent) {
        changes_[changeAt_[k]] = {instance.id, instance.mesh, instance.pose};
        changeOf_[instance.id] = changeAt_[k];
      }
      instance.pose = poses[k];
      instance.movedThisFrame = true;
    });
    return;
  }
  // Repeated ids: the record serially (a lookup and, for an instance's first change of the frame,
  // a copy of its start pose); each slot remembers the last pair moving it, so that a repeated id
  // stores its last pose alone and no two tasks write one instance.
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const std::uint32_t slot = slot_[ids[k]];
    recordChange(instances_[slot], true);
    lastMove_[slot] = std::uint32_t(k);
  }
  each([&](std::size_t k) {
    const std::uint32_t slot = slot_[ids[k]];
    if (lastMove_[slot] != k) return;
    instances_[slot].pose = poses[k];
    instances_[slot].movedThisFrame = true;
  });
}

void InstanceSet::remove(InstanceId id) {
  const std::uint32_t slot = slotOf(id);
  recordChange(instances_[slot], true);
  if (slot + 1 != instances_.size()) {
    instances_[slot] = instances_.back();
    slot_[instances_[slot].id] = slot;
  }
  instances_.pop_back();
  slot_[id] = kAbsent;
}

bool InstanceSet::contains(InstanceId id) const {
  return id < slot_.size() && slot_[id] != kAbsent;
}

const Instance* InstanceSet::find(InstanceId id) const {
  return contains(id) ? &instances_[slot_[id]] : nullptr;
}

void InstanceSet::recordChange(const Instance& instance, bool existedBefore) {
  if (changeOf_[instance.id] != kAbsent) return;  // the frame's start pose is already kept
  changeOf_[instance.id] = std::uint32_t(changes_.size());
  changes_.push_back(
      {instance.id, instance.mesh, existedBefore ? std::optional(instance.pose) : std::nullopt});
}

std::vector<WorldBox> InstanceSet::changedBoxes(const ObjectLibrary& lib) const {
  std::vector<WorldBox> boxes;
  boxes.reserve(changes_.size() * 2);
  for (const Change& c : changes_) {
    const ObjectSdf& sdf = lib.mesh(c.mesh);
    if (c.before) boxes.push_back(worldBoundsOf(sdf, *c.before));
    if (const Instance* now = find(c.id)) boxes.push_back(worldBoundsOf(sdf, now->pose));
  }
  return boxes;
}

std::vector<WorldBox> InstanceSet::changedBounds(const ObjectLibrary& lib) const {
  std::vector<WorldBox> out;
  changedBounds(lib, out);
  return out;
}

void InstanceSet::changedBounds(const ObjectLibrary& lib, std::vector<WorldBox>& out) const {
  for (const Change& c : changes_) lib.mesh(c.mesh);  // an unknown mesh throws here, not in a task
  // One slot per change, filled in parallel (an empty box where the instance existed at neither
  // end), then compacted in place: no per-frame allocation once `out` has grown.
  out.resize(changes_.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, changes_.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const Change& c = changes_[i];
                        const ObjectSdf& sdf = lib.mesh(c.mesh);
                        WorldBox b{glm::dvec3(INFINITY), glm::dvec3(-INFINITY)};
                        if (c.before) b = boundsOfValid(sdf, *c.before);
                        if (const Instance* now = find(c.id)) {
                          const WorldBox n = boundsOfValid(sdf, now->pose);
                          b = WorldBox{glm::min(b.min, n.min), glm::max(b.max, n.max)};
                        }
                        out[i] = b;
                      }
                    });
  std::size_t kept = 0;
  for (std::size_t i = 0; i < out.size(); ++i)
    if (out[i].min.x <= out[i].max.x) out[kept++] = out[i];
  out.resize(kept);
}

void InstanceSet::endFrame() {
  // Only changed instances can have the flag set: O(changes), not O(instances). Each change is
  // of its own id, so the changes are reset in parallel without two tasks writing one entry.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, changes_.size(), 2048),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const InstanceId id = changes_[i].id;
                        changeOf_[id] = kAbsent;
                        if (contains(id)) instances_[slot_[id]].movedThisFrame = false;
                      }
                    });
  changes_.clear();
}

}  // namespace sdfstream
