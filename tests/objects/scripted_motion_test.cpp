// ScriptedMotion: each mover's path (orbit radius, fall above the floor, loop speed), apply only
// moving what changed, and spreadObjects deterministic from its seed.
#include <cmath>
#include <numbers>

#include <set>

#include <gtest/gtest.h>

#include "objects/scripted_motion.h"
#include "tests/support/object_sdf_settings.h"

namespace sdfstream {
namespace {

TEST(ScriptedMotion, OrbitKeepsItsRadiusAndPeriod) {
  ScriptedMotion motion;
  const Orbit orbit{glm::dvec3(5, 2, -3), 4.0, 8.0, 0.25};
  const glm::quat rotation = glm::angleAxis(0.3f, glm::vec3(1, 0, 0));
  const std::size_t i = motion.add(7, orbit, rotation, glm::vec3(2, 1, 1));
  EXPECT_EQ(motion.instance(i), 7u);
  for (double t = -3.0; t < 20.0; t += 0.37) {
    const ObjectTransform pose = motion.poseAt(i, t);
    const glm::dvec3 d = pose.translation - orbit.centre;
    EXPECT_NEAR(std::hypot(d.x, d.z), orbit.radius, 1e-9) << t;
    EXPECT_EQ(d.y, 0.0);
    EXPECT_EQ(pose.rotation, rotation);
    EXPECT_EQ(pose.scale, glm::vec3(2, 1, 1));
    EXPECT_NEAR(glm::length(motion.poseAt(i, t + orbit.period).translation - pose.translation), 0.0,
                1e-9);
  }
  // Phase 0.25 at t = 0: a quarter turn counter-clockwise from +x seen from above, i.e. at −z.
  const glm::dvec3 start = motion.poseAt(i, 0.0).translation - orbit.centre;
  EXPECT_NEAR(start.x, 0.0, 1e-9);
  EXPECT_NEAR(start.z, -orbit.radius, 1e-9);
  // Half a period later: the opposite side.
  EXPECT_NEAR(glm::length(motion.poseAt(i, 4.0).translation - orbit.centre + start), 0.0, 1e-9);
}

TEST(ScriptedMotion, FallDropsUnderGravityStaysAboveTheFloorAndRestarts) {
  ScriptedMotion motion;
  Fall fall;
  fall.start = {1, 10, 2};
  fall.floorHeight = 2.0;
  fall.period = 3.0;  // the drop of 8 m takes sqrt(16 / 9.81) = 1.28 s
  fall.spinRate = 0.4;
  const std::size_t i = motion.add(0, fall);
  bool landed = false;
  for (double t = 0; t < 9.0; t += 0.01) {
    const ObjectTransform pose = motion.poseAt(i, t);
    ASSERT_GE(pose.translation.y, fall.floorHeight) << t;
    ASSERT_LE(pose.translation.y, fall.start.y) << t;
    EXPECT_EQ(pose.translation.x, 1.0);
    landed |= pose.translation.y == fall.floorHeight;
    const double tau = std::fmod(t, fall.period);
    EXPECT_NEAR(pose.translation.y, std::max(2.0, 10.0 - 0.5 * kGravity * tau * tau), 1e-9) << t;
    // Spins slowly about +y: the rotation angle grows with t.
    EXPECT_NEAR(glm::angle(glm::dquat(pose.rotation)),
                std::fmod(fall.spinRate * t, 2 * std::numbers::pi), 1e-4)
        << t;
  }
  EXPECT_TRUE(landed);
  EXPECT_EQ(motion.poseAt(i, 0.0).translation.y, 10.0);
  EXPECT_EQ(motion.poseAt(i, 3.0).translation.y, 10.0);  // restarted
}

TEST(ScriptedMotion, PathRunsTheLoopAtConstantSpeed) {
  ScriptedMotion motion;
  Path path{{{0, 0, 0}, {4, 0, 0}, {4, 0, 3}, {0, 0, 3}}, 2.0, 0.0};  // 14 m loop, 7 s
  const std::size_t i = motion.add(0, path);
  EXPECT_EQ(motion.poseAt(i, 0.0).translation, glm::dvec3(0, 0, 0));
  EXPECT_NEAR(glm::length(motion.poseAt(i, 2.0).translation - glm::dvec3(4, 0, 0)), 0, 1e-9);
  EXPECT_NEAR(glm::length(motion.poseAt(i, 2.5).translation - glm::dvec3(4, 0, 1)), 0, 1e-9);
  EXPECT_NEAR(glm::length(motion.poseAt(i, 6.5).translation - glm::dvec3(0, 0, 1)), 0, 1e-9);
  EXPECT_NEAR(glm::length(motion.poseAt(i, 7.0).translation), 0, 1e-9);
  // Constant speed: consecutive small steps (within a segment) cover speed·dt.
  for (double t = 0.05; t < 7; t += 0.5)
    EXPECT_NEAR(
        glm::length(motion.poseAt(i, t + 0.01).translation - motion.poseAt(i, t).translation), 0.02,
        1e-9)
        << t;
  path.phase = 0.5;  // half the loop ahead: (4, 0, 3)
  EXPECT_NEAR(
      glm::length(motion.poseAt(motion.add(1, path), 0.0).translation - glm::dvec3(4, 0, 3)), 0,
      1e-9);
}

TEST(ScriptedMotion, InvalidMoversThrow) {
  ScriptedMotion motion;
  EXPECT_THROW(motion.add(0, Orbit{glm::dvec3(0), 1, 0, 0}), std::invalid_argument);
  EXPECT_THROW(motion.add(0, Orbit{glm::dvec3(0), -1, 1, 0}), std::invalid_argument);
  Fall fall;
  fall.floorHeight = 1;  // above start
  EXPECT_THROW(motion.add(0, fall), std::invalid_argument);
  EXPECT_THROW(motion.add(0, Path{{{1, 1, 1}}, 1, 0}), std::invalid_argument);
  EXPECT_THROW(motion.add(0, Path{{{1, 1, 1}, {1, 1, 1}}, 1, 0}), std::invalid_argument);
  EXPECT_THROW(motion.add(0, Orbit{}, glm::quat(1, 0, 0, 0), glm::vec3(1, 0, 1)),
               std::invalid_argument);
  EXPECT_EQ(motion.size(), 0u);
}

TEST(ScriptedMotion, ApplyMovesOnlyWhatChanged) {
  InstanceSet set;
  const InstanceId moving = set.add(0, ObjectTransform{}), still = set.add(0, ObjectTransform{});
  const InstanceId gone = set.add(0, ObjectTransform{});
  ScriptedMotion motion;
  motion.add(moving, Orbit{glm::dvec3(0), 2.0, 5.0, 0.0});
  motion.add(still, Orbit{glm::dvec3(1, 2, 3), 0.0, 5.0, 0.0});  // radius 0: never moves
  motion.add(gone, Orbit{glm::dvec3(0), 1.0, 5.0, 0.0});
  set.remove(gone);  // skipped from now on
  motion.apply(set, 0.0);
  EXPECT_EQ(set.find(still)->pose.translation, glm::dvec3(1, 2, 3));
  set.endFrame();
  motion.apply(set, 0.0);  // same time: nothing changes
  EXPECT_FALSE(set.find(moving)->movedThisFrame);
  EXPECT_FALSE(set.find(still)->movedThisFrame);
  motion.apply(set, 1.0);
  EXPECT_TRUE(set.find(moving)->movedThisFrame);
  EXPECT_FALSE(set.find(still)->movedThisFrame);
  EXPECT_EQ(set.find(moving)->pose, motion.poseAt(0, 1.0));
  EXPECT_EQ(set.size(), 2u);
}

// Everything spreadObjects makes, as comparable values.
std::vector<std::pair<std::uint32_t, ObjectTransform>> snapshot(const InstanceSet& set) {
  std::vector<std::pair<std::uint32_t, ObjectTransform>> out;
  for (const Instance& inst : set.instances()) out.push_back({inst.mesh, inst.pose});
  return out;
}

TEST(SpreadObjects, DeterministicFromTheSeedAndSpreadOverTheArea) {
  const WorldBox area{glm::dvec3(-50, 0, -50), glm::dvec3(50, 20, 50)};
  ObjectLibrary libA(test::objectSdfResolution(8, 8)), libB(test::objectSdfResolution(8, 8));
  InstanceSet a, b, c;
  const ScriptedMotion ma = spreadObjects(a, libA, 600, area, 1234);
  const ScriptedMotion mb = spreadObjects(b, libB, 600, area, 1234);
  EXPECT_EQ(libA.size(), 2u);  // two primitives, not one per instance
  EXPECT_EQ(ma.size(), 600u);
  EXPECT_EQ(snapshot(a), snapshot(b));
  for (double t : {0.5, 3.25, 100.0}) {
    ma.apply(a, t);
    mb.apply(b, t);
    ASSERT_EQ(snapshot(a), snapshot(b)) << t;
  }
  spreadObjects(c, libA, 600, area, 4321);  // reuses the library's primitives
  EXPECT_EQ(libA.size(), 2u);
  EXPECT_NE(snapshot(c), snapshot(a));

  // The mix: both meshes, all three movers, sizes 0.3–2 m, starts spread over the area.
  InstanceSet fresh;
  const ScriptedMotion m = spreadObjects(fresh, libA, 600, area, 99);
  int meshes[2] = {0, 0}, movers[3] = {0, 0, 0};
  int octants[8] = {};
  for (std::size_t i = 0; i < m.size(); ++i) {
    const Instance* inst = fresh.find(m.instance(i));
    ASSERT_NE(inst, nullptr);
    ++meshes[inst->mesh == *libA.find("spread:box") ? 0 : 1];
    ++movers[m.mover(i).index()];
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_GE(inst->pose.scale[axis], 0.3f);
      EXPECT_LE(inst->pose.scale[axis], 2.0f);
    }
    EXPECT_EQ(inst->pose, m.poseAt(i, 0.0));  // starts at its t = 0 pose
    const glm::dvec3 p = inst->pose.translation;
    ++octants[(p.x > 0) + 2 * (p.y > 10) + 4 * (p.z > 0)];
    // Falls never drop below their floor, which keeps the whole object above the area.
    if (const Fall* f = std::get_if<Fall>(&m.mover(i))) {
      EXPECT_GE(f->floorHeight - 0.5 * glm::length(glm::dvec3(inst->pose.scale)),
                area.min.y - 1e-9);
      for (double t = 0; t < 10; t += 0.25) ASSERT_GE(m.poseAt(i, t).translation.y, f->floorHeight);
    }
  }
  EXPECT_GT(meshes[0], 200);
  EXPECT_GT(meshes[1], 200);
  for (int k : movers) EXPECT_GT(k, 120);
  for (int k : octants) EXPECT_GT(k, 30);
}

// More meshes (the cards' per-mesh cost): each is made once, with its own shape, and used;
// the instances' poses are drawn as with two.
TEST(SpreadObjects, MoreMeshesAreAllUsedAndMadeOnce) {
  const WorldBox area{glm::dvec3(-50, 0, -50), glm::dvec3(50, 20, 50)};
  ObjectLibrary lib(test::objectSdfResolution(8, 8));
  InstanceSet set;
  const ScriptedMotion m = spreadObjects(set, lib, 600, area, 7, 10);
  ASSERT_EQ(lib.size(), 10u);
  std::vector<int> used(10, 0);
  for (const Instance& inst : set.instances()) ++used.at(inst.mesh);
  for (std::uint32_t k = 0; k < 10; ++k) EXPECT_GT(used[k], 20) << "mesh " << k;
  std::set<std::pair<float, float>> shapes;  // (height, width) of each mesh's bounds
  for (std::uint32_t k = 0; k < 10; ++k) {
    const TriangleScene& t = lib.triangles(k);
    shapes.insert({t.boundsMax().y - t.boundsMin().y, t.boundsMax().x - t.boundsMin().x});
  }
  EXPECT_EQ(shapes.size(), 9u);  // only the unit box and the unit sphere share bounds (1, 1)
  InstanceSet again;
  spreadObjects(again, lib, 600, area, 7, 10);  // reuses them
  EXPECT_EQ(lib.size(), 10u);
  EXPECT_EQ(m.size(), 600u);
}

TEST(SpreadObjects, BadAreaThrows) {
  ObjectLibrary lib(test::objectSdfResolution(8, 8));
  InstanceSet set;
  EXPECT_THROW(spreadObjects(set, lib, 3, WorldBox{glm::dvec3(1), glm::dvec3(0)}, 1),
               std::invalid_argument);
  // A flat area (no room for loops) still works.
  const ScriptedMotion m =
      spreadObjects(set, lib, 30, WorldBox{glm::dvec3(0), glm::dvec3(0, 5, 0)}, 1);
  EXPECT_EQ(set.size(), 30u);
  m.apply(set, 2.0);
}

}  // namespace
}  // namespace sdfstream
