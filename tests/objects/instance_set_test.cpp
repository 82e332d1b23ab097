// InstanceSet: stable ids, O(1) swap-remove, the per-frame change record and its world boxes, and
// ObjectTransform / worldBoundsOf.
#include <algorithm>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "objects/instance_set.h"
#include "tests/support/object_sdf_settings.h"

namespace sdfstream {
namespace {

ObjectTransform at(double x, double y = 0, double z = 0) {
  ObjectTransform t;
  t.translation = {x, y, z};
  return t;
}

bool sameBox(const WorldBox& a, const WorldBox& b, double eps = 1e-9) {
  return glm::all(glm::lessThanEqual(glm::abs(a.min - b.min), glm::dvec3(eps))) &&
         glm::all(glm::lessThanEqual(glm::abs(a.max - b.max), glm::dvec3(eps)));
}

bool contains(const std::vector<WorldBox>& boxes, const WorldBox& box) {
  return std::any_of(boxes.begin(), boxes.end(),
                     [&](const WorldBox& b) { return sameBox(b, box); });
}

TEST(ObjectTransform, MatrixIsTranslateRotateScale) {
  ObjectTransform t;
  t.translation = {10, 20, 30};
  t.rotation = glm::angleAxis(float(M_PI / 2), glm::vec3(0, 0, 1));  // x → y
  t.scale = {2, 3, 4};
  const glm::dvec3 p(t.matrix() * glm::dvec4(1, 1, 1, 1));
  // S: (2,3,4); R (90° about z): (−3, 2, 4); T: (7, 22, 34).
  EXPECT_NEAR(p.x, 7, 1e-6);
  EXPECT_NEAR(p.y, 22, 1e-6);
  EXPECT_NEAR(p.z, 34, 1e-6);
  ObjectTransform unnormalised = t;
  unnormalised.rotation = t.rotation * 3.0f;  // normalised before use
  const glm::dvec3 q(unnormalised.matrix() * glm::dvec4(1, 1, 1, 1));
  EXPECT_NEAR(glm::length(q - p), 0.0, 1e-6);
}

TEST(ObjectTransform, InvalidScaleOrRotationThrows) {
  InstanceSet set;
  for (glm::vec3 scale : {glm::vec3(0, 1, 1), glm::vec3(1, NAN, 1), glm::vec3(1, 1, INFINITY)}) {
    ObjectTransform t;
    t.scale = scale;
    EXPECT_THROW(t.matrix(), std::invalid_argument);
    EXPECT_THROW(set.add(0, t), std::invalid_argument);
  }
  ObjectTransform zeroRotation;
  zeroRotation.rotation = glm::quat(0, 0, 0, 0);
  EXPECT_THROW(set.add(0, zeroRotation), std::invalid_argument);
  EXPECT_THROW(set.add(0, at(NAN)), std::invalid_argument);
  EXPECT_EQ(set.size(), 0u);
  const InstanceId id = set.add(0, at(1));
  ObjectTransform bad;
  bad.scale.z = 0;
  EXPECT_THROW(set.move(id, bad), std::invalid_argument);
  EXPECT_EQ(set.find(id)->pose, at(1));  // unchanged
  ObjectTransform mirrored;
  mirrored.scale = {-1, 1, 1};  // negative scale is allowed
  EXPECT_NO_THROW(set.move(id, mirrored));
}

TEST(WorldBounds, ExactBoxOfTheTransformedGridCorners) {
  ObjectLibrary lib(test::objectSdfResolution(8, 8));
  const ObjectSdf& sdf = lib.mesh(lib.addBox(glm::vec3(1.0f, 0.5f, 0.25f), glm::vec4(1.0f)));
  ObjectTransform t;
  t.translation = {100, -5, 3};
  t.rotation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 2, -1)));
  t.scale = {1.5f, 0.5f, 2.0f};
  const WorldBox box = worldBoundsOf(sdf, t);
  // Every sample of the grid, transformed, lies inside; each face of the box is touched by one.
  const glm::dmat4 m = t.matrix();
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (std::uint32_t z = 0; z < sdf.dims.z; ++z)
    for (std::uint32_t y = 0; y < sdf.dims.y; ++y)
      for (std::uint32_t x = 0; x < sdf.dims.x; ++x) {
        const glm::dvec3 w(m * glm::dvec4(glm::dvec3(sdf.samplePosition(x, y, z)), 1.0));
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
      }
  EXPECT_TRUE(sameBox(box, WorldBox{lo, hi}, 1e-5));
  // Identity pose: the grid box itself.
  const WorldBox identity = worldBoundsOf(sdf, ObjectTransform{});
  EXPECT_TRUE(sameBox(identity, WorldBox{glm::dvec3(sdf.gridMin), glm::dvec3(sdf.gridMax())}));
}

TEST(InstanceSet, AddMoveRemoveWithStableIdsAndSwapRemove) {
  InstanceSet set;
  std::vector<InstanceId> ids;
  for (int i = 0; i < 5; ++i) ids.push_back(set.add(std::uint32_t(i % 2), at(i)));
  EXPECT_EQ(ids, (std::vector<InstanceId>{0, 1, 2, 3, 4}));
  EXPECT_EQ(set.size(), 5u);
  for (const Instance& inst : set.instances()) EXPECT_TRUE(inst.movedThisFrame);

  set.remove(ids[1]);  // swap-remove: the last instance takes slot 1
  EXPECT_EQ(set.size(), 4u);
  EXPECT_FALSE(set.contains(ids[1]));
  EXPECT_EQ(set.find(ids[1]), nullptr);
  for (int i : {0, 2, 3, 4}) {
    ASSERT_TRUE(set.contains(ids[i]));
    const Instance* inst = set.find(ids[i]);
    EXPECT_EQ(inst->id, ids[i]);
    EXPECT_EQ(inst->mesh, std::uint32_t(i % 2));
    EXPECT_EQ(inst->pose, at(i));
  }
  const InstanceId fresh = set.add(7, at(9));
  EXPECT_EQ(fresh, 5u);  // never reused
  set.move(ids[4], at(40));
  EXPECT_EQ(set.find(ids[4])->pose, at(40));
  EXPECT_EQ(set.find(ids[3])->pose, at(3));

  try {
    set.move(ids[1], at(0));
    ADD_FAILURE() << "moved a removed instance";
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("id 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(set.remove(ids[1]), std::out_of_range);
  EXPECT_THROW(set.move(99, at(0)), std::out_of_range);

  // Removing everything, in an order that exercises the last-slot case too.
  for (InstanceId id : {ids[0], fresh, ids[3], ids[2], ids[4]}) set.remove(id);
  EXPECT_EQ(set.size(), 0u);
  EXPECT_EQ(set.add(0, at(0)), 6u);
}

TEST(InstanceSet, RandomOperationsAgreeWithAMap) {
  InstanceSet set;
  std::map<InstanceId, std::pair<std::uint32_t, double>> model;
  std::mt19937 rng(5);
  for (int step = 0; step < 3000; ++step) {
    const int op = int(rng() % 3);
    if (op == 0 || model.empty()) {
      const std::uint32_t mesh = rng() % 4;
      const double x = double(rng() % 1000);
      model[set.add(mesh, at(x))] = {mesh, x};
    } else {
      auto it = model.begin();
      std::advance(it, rng() % model.size());
      if (op == 1) {
        const double x = double(rng() % 1000);
        set.move(it->first, at(x));
        it->second.second = x;
      } else {
        set.remove(it->first);
        model.erase(it);
      }
    }
    if (step % 97 == 0) set.endFrame();
  }
  ASSERT_EQ(set.size(), model.size());
  for (const Instance& inst : set.instances()) {
    ASSERT_TRUE(model.count(inst.id));
    EXPECT_EQ(inst.mesh, model[inst.id].first);
    EXPECT_EQ(inst.pose.translation.x, model[inst.id].second);
  }
}

TEST(InstanceSet, BatchMoveEqualsMovingEachPairInOrder) {
  ObjectLibrary lib(test::objectSdfResolution(8, 8));
  const std::uint32_t mesh = lib.addBox(glm::vec3(0.5f), glm::vec4(1.0f));
  InstanceSet batched, oneByOne;
  std::vector<InstanceId> ids;
  for (int i = 0; i < 5000; ++i) {
    ids.push_back(batched.add(mesh, at(i)));
    oneByOne.add(mesh, at(i));
  }
  std::mt19937 rng(11);
  for (int frame = 0; frame < 4; ++frame) {
    batched.endFrame();
    oneByOne.endFrame();
    // Several batches a frame: distinct ids in a shuffled order (the parallel record), then
    // repeated ids inside a batch and across batches (the serial one): the last pose wins, the
    // record keeps the frame's start pose, in order of first change.
    for (int batch = 0; batch < 4; ++batch) {
      std::vector<InstanceId> moveIds;
      std::vector<ObjectTransform> poses;
      std::vector<InstanceId> shuffled = ids;
      std::shuffle(shuffled.begin(), shuffled.end(), rng);
      for (int k = 0; k < 3000; ++k) {
        moveIds.push_back(batch % 2 == 0 ? shuffled[k] : ids[rng() % ids.size()]);
        poses.push_back(at(double(rng() % 100000) / 8.0, frame, batch));
      }
      batched.move(moveIds, poses);
      for (std::size_t k = 0; k < moveIds.size(); ++k) oneByOne.move(moveIds[k], poses[k]);
    }
    const std::vector<WorldBox> a = batched.changedBoxes(lib), b = oneByOne.changedBoxes(lib);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) ASSERT_TRUE(sameBox(a[k], b[k], 0.0)) << k;
    for (InstanceId id : ids) {
      ASSERT_EQ(batched.find(id)->pose, oneByOne.find(id)->pose) << id;
      ASSERT_EQ(batched.find(id)->movedThisFrame, oneByOne.find(id)->movedThisFrame) << id;
    }
  }
}

TEST(InstanceSet, BatchMoveMovesNothingWhenAnyPairIsBad) {
  ObjectLibrary lib(test::objectSdfResolution(8, 8));
  const std::uint32_t mesh = lib.addBox(glm::vec3(0.5f), glm::vec4(1.0f));
  InstanceSet set;
  std::vector<InstanceId> ids;
  for (int i = 0; i < 3000; ++i) ids.push_back(set.add(mesh, at(i)));
  set.remove(ids[7]);
  set.endFrame();
  std::vector<ObjectTransform> poses(ids.size(), at(-5));
  std::vector<InstanceId> valid = ids;
  valid[7] = ids[8];
  ObjectTransform flat = at(1);
  flat.scale.y = 0.0f;
  std::vector<ObjectTransform> withFlat = poses;
  withFlat[2999] = flat;
  EXPECT_THROW(set.move(ids, poses), std::out_of_range);           // ids[7] was removed
  EXPECT_THROW(set.move(valid, withFlat), std::invalid_argument);  // a zero scale
  EXPECT_THROW(set.move(valid, std::span(poses).first(10)), std::invalid_argument);  // lengths
  EXPECT_TRUE(set.changedBoxes(lib).empty());
  for (const Instance& inst : set.instances()) {
    EXPECT_FALSE(inst.movedThisFrame);
    EXPECT_EQ(inst.pose.translation.x, double(inst.id));
  }
}

TEST(InstanceSet, ChangedBoxesCoverOldAndNewPosesUntilEndFrame) {
  ObjectLibrary lib(test::objectSdfResolution(8, 8));
  const std::uint32_t mesh = lib.addBox(glm::vec3(0.5f), glm::vec4(1.0f));
  const ObjectSdf& sdf = lib.mesh(mesh);
  InstanceSet set;
  const InstanceId a = set.add(mesh, at(0)), b = set.add(mesh, at(10)), c = set.add(mesh, at(20));
  std::vector<WorldBox> boxes = set.changedBoxes(lib);
  ASSERT_EQ(boxes.size(), 3u);  // added: new pose only
  for (double x : {0.0, 10.0, 20.0}) EXPECT_TRUE(contains(boxes, worldBoundsOf(sdf, at(x))));

  set.endFrame();
  EXPECT_TRUE(set.changedBoxes(lib).empty());
  for (const Instance& inst : set.instances()) EXPECT_FALSE(inst.movedThisFrame);

  set.move(a, at(1));
  set.move(a, at(2));  // twice: the frame's start and end poses only
  set.remove(b);
  boxes = set.changedBoxes(lib);
  ASSERT_EQ(boxes.size(), 3u);
  EXPECT_TRUE(contains(boxes, worldBoundsOf(sdf, at(0))));
  EXPECT_TRUE(contains(boxes, worldBoundsOf(sdf, at(2))));
  EXPECT_TRUE(contains(boxes, worldBoundsOf(sdf, at(10))));  // removed: old pose
  EXPECT_FALSE(contains(boxes, worldBoundsOf(sdf, at(1))));
  EXPECT_FALSE(contains(boxes, worldBoundsOf(sdf, at(20))));  // untouched
  EXPECT_TRUE(set.find(a)->movedThisFrame);
  EXPECT_FALSE(set.find(c)->movedThisFrame);

  set.endFrame();
  EXPECT_TRUE(set.changedBoxes(lib).empty());
  EXPECT_FALSE(set.find(a)->movedThisFrame);

  // Added and removed within one frame: nothing to refresh.
  const InstanceId d = set.add(mesh, at(50));
  set.remove(d);
  EXPECT_TRUE(set.changedBoxes(lib).empty());
  // Moved then removed: the start pose only.
  set.move(c, at(30));
  set.remove(c);
  boxes = set.changedBoxes(lib);
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_TRUE(sameBox(boxes[0], worldBoundsOf(sdf, at(20))));

  // An instance of a mesh the library lacks is a programmer error.
  set.endFrame();
  set.add(99, at(0));
  EXPECT_THROW(set.changedBoxes(lib), std::out_of_range);
}

TEST(InstanceSet, ChangedBoundsMergeEachChangesStartAndEndBoxes) {
  ObjectLibrary lib(test::objectSdfResolution(8, 8));
  const std::uint32_t mesh = lib.addBox(glm::vec3(0.5f), glm::vec4(1.0f));
  const ObjectSdf& sdf = lib.mesh(mesh);
  InstanceSet set;
  const InstanceId a = set.add(mesh, at(0)), b = set.add(mesh, at(10));
  set.add(mesh, at(20));
  set.endFrame();
  set.move(a, at(3));
  set.remove(b);
  const InstanceId d = set.add(mesh, at(40));
  set.move(d, at(41));
  const std::vector<WorldBox> bounds = set.changedBounds(lib);
  ASSERT_EQ(bounds.size(), 3u);  // one per changed instance that existed at either end
  const WorldBox from0 = worldBoundsOf(sdf, at(0)), to3 = worldBoundsOf(sdf, at(3));
  EXPECT_TRUE(
      sameBox(bounds[0], WorldBox{glm::min(from0.min, to3.min), glm::max(from0.max, to3.max)}));
  EXPECT_TRUE(sameBox(bounds[1], worldBoundsOf(sdf, at(10))));  // removed: its start pose
  EXPECT_TRUE(sameBox(bounds[2], worldBoundsOf(sdf, at(41))));  // added: its end pose
  // Every box changedBoxes reports lies inside one of the merged bounds.
  for (const WorldBox& box : set.changedBoxes(lib)) {
    bool inside = false;
    for (const WorldBox& m : bounds)
      inside = inside || (glm::all(glm::greaterThanEqual(box.min, m.min)) &&
                          glm::all(glm::lessThanEqual(box.max, m.max)));
    EXPECT_TRUE(inside);
  }
  set.endFrame();
  EXPECT_TRUE(set.changedBounds(lib).empty());
}

}  // namespace
}  // namespace sdfstream
