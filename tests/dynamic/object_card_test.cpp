// Cards of moving objects in the GI (cards/, card_light.comp, card_lookup.glsl): the card light
// pass lights each texel with the sun as the analytic Lambert term, shadowed by another object;
// the pass and the lookup a ray's hit makes equal their CPU references (card_light.glsl and
// card_lookup.glsl compiled as C++) texel for texel; the light blocks are
// allocated without drift under churn and relit moved-first within the budget.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include "gi/card_light_slots.h"
#include "gi/gpu_stack_scene.h"
#include "gi/light_cache.h"
#include "gi/object_scene.h"
#include "gi/object_scene_cpu.h"
#include "tests/dynamic/object_scenes.h"
#include "tests/lights/light_scenes.h"
#include "tests/support/analytic_stack.h"
#include "tests/support/gpu_test.h"

namespace sdfstream {
namespace {
namespace gs = gpu_shared;

class ObjectCardTest : public test::GpuTest {};

test::AnalyticStack floorStack() {
  return test::AnalyticStack(
      1, [](glm::vec3 p, float) { return test::sdFloor(p); },
      [](glm::vec3) { return test::uniformMaterial(test::rgba8(200, 200, 200), 0u); });
}

// The instance's card texels as (texel, light) pairs, face by face.
struct InstanceCards {
  std::vector<gs::CardTexelGpu> texels[6];
  std::vector<glm::vec3> light[6];
};

InstanceCards instanceCards(const ObjectScene& scene, std::uint32_t instance) {
  InstanceCards out;
  const std::vector<std::uint32_t> light = scene.downloadCardLight();
  const gs::ObjectInstanceGpu& inst = scene.frame().instances.at(instance);
  const std::uint32_t tableWords = std::uint32_t(scene.cardTable().size()) * 4u;
  const std::uint32_t base = inst.info.w & gs::kCardLightBaseMask;
  const std::uint32_t level = inst.info.w >> gs::kCardLightLevelShift;
  for (std::uint32_t k = 0; k < 6; ++k) {
    const gs::CardGpu& c = scene.cardTable()[inst.info.x * 6 + k];
    for (std::uint32_t t = 0; t < c.info.z * c.info.w; ++t) {
      const std::uint32_t local = c.first.x + t;
      out.texels[k].push_back(scene.cardTexels()[c.first.y - tableWords + local]);
      const std::uint32_t lit = gs::cardLightIndex(c, level, t % c.info.z, t / c.info.z);
      out.light[k].push_back(gs::unpackRgb9e5(light.at(base + lit)));
    }
  }
  return out;
}

TEST_F(ObjectCardTest, CardLightIsTheSunsLambertTermAndAnotherObjectShadowsIt) {
  test::AnalyticStack stack = floorStack();
  const CascadeStackImage& image = stack.image;
  GpuStackScene scene(ctx());
  scene.uploadAll(image);
  LightCache cache(ctx());
  const glm::vec3 towardsSun = glm::normalize(glm::vec3(0.4f, 1.0f, 0.2f));
  const std::vector<gs::GpuLight> lights = {test::sunLight(towardsSun, 3.0f)};
  const gs::GpuSky sky{};
  const glm::vec4 red(0.8f, 0.1f, 0.1f, 1.0f);
  ObjectLibrary library(ObjectSdfSettings{16, 32, 0.0, 2});
  const std::uint32_t box = library.addBox({4.0f, 4.0f, 4.0f}, red);
  InstanceSet instances;
  ObjectTransform pose;
  pose.translation = glm::dvec3(64.0, 50.0, 64.0);  // 8 m cube, 6 m above the floor
  instances.add(box, pose);
  ObjectScene objects(ctx());
  auto frame = [&] {
    objects.update(library, instances, image);
    cache.update(scene, lights, sky, {}, image.voxelSize0, &objects);
    instances.endFrame();
  };
  frame();
  ASSERT_EQ(objects.cardRelightCount(), 1u);
  const InstanceCards lit = instanceCards(objects, 0);
  // Every texel of a face sees that face; its light is albedo/π · 3 · max(0, n·L).
  std::size_t checked = 0;
  float worst = 0.0f;
  for (std::uint32_t k = 0; k < 6; ++k) {
    glm::vec3 n(0.0f);
    n[k / 2] = k % 2 == 0 ? 1.0f : -1.0f;
    for (std::size_t t = 0; t < lit.texels[k].size(); ++t) {
      const gs::CardTexelGpu& texel = lit.texels[k][t];
      ASSERT_GE(texel.depth, 0.0f);
      EXPECT_GT(glm::dot(gs::cardUnpackNormal(texel.normal), n), 0.9999f);
      const glm::vec3 albedo(test::srgbToLinear(float(texel.albedo & 255u) / 255.0f),
                             test::srgbToLinear(float((texel.albedo >> 8) & 255u) / 255.0f),
                             test::srgbToLinear(float((texel.albedo >> 16) & 255u) / 255.0f));
      const glm::vec3 expected =
          albedo * (3.0f * std::max(0.0f, glm::dot(n, towardsSun)) / 3.14159265f);
      const glm::vec3 got = lit.light[k][t];
      for (int ch = 0; ch < 3; ++ch) {
        const float err = std::abs(got[ch] - expected[ch]);
        worst = std::max(worst, err / std::max(expected[ch], 0.01f));
        EXPECT_LE(err, 0.01f * expected[ch] + 1e-3f) << "card " << k << " texel " << t;
      }
      ++checked;
    }
  }
  std::printf("[figures] card light vs Lambert: %zu texels, worst relative error %.4f\n", checked,
              worst);

  // An 8 x 2 x 8 m slab 15 m above the cube's top face, shifted towards the sun so its shadow
  // covers the whole top face (+y card, k = 2) and leaves the +x face (k = 0) mostly lit.
  ObjectTransform slabPose;
  slabPose.translation = glm::dvec3(64.0 + 6.0, 70.0, 64.0 + 3.0);
  slabPose.scale = glm::vec3(1.0f, 0.25f, 1.0f);
  instances.add(box, slabPose);
  frame();
  const InstanceCards shadowed = instanceCards(objects, 0);
  double before = 0.0, after = 0.0;
  for (std::size_t t = 0; t < shadowed.light[2].size(); ++t) {
    before += lit.light[2][t].x;
    after += shadowed.light[2][t].x;
  }
  std::printf("[figures] top face under the slab: %.4f of its sunlit light\n", after / before);
  EXPECT_GT(before, 0.0);
  EXPECT_LT(after, 0.01 * before);
  // The sides the slab does not shade keep their light (the +x face, k = 0).
  double side = 0.0, sideBefore = 0.0;
  for (std::size_t t = 0; t < shadowed.light[0].size(); ++t) {
    side += shadowed.light[0][t].x;
    sideBefore += lit.light[0][t].x;
  }
  EXPECT_GT(side, 0.5 * sideBefore);

  // The pass counts light that came out non-finite (RGB9E5 would show it as white or black):
  // none so far; two suns of 3e38 overflow a float on every texel facing them.
  EXPECT_EQ(objects.cardNonFiniteTexels(), 0u);
  const std::vector<gs::GpuLight> blinding = {test::sunLight(towardsSun, 3e38f),
                                              test::sunLight(towardsSun, 3e38f)};
  objects.update(library, instances, image);
  cache.update(scene, blinding, sky, {}, image.voxelSize0, &objects);
  const std::uint64_t overflowed = objects.cardNonFiniteTexels();
  std::printf("[figures] two suns of 3e38: %llu card texels counted non-finite\n",
              (unsigned long long)overflowed);
  EXPECT_GT(overflowed, 0u);
}

// The card light pass and the lookup against their CPU references, for 60 random objects with
// their light at full resolution (levelDistance 0) or at levels by distance.
void expectCardsEqualTheCpuReference(gpu::Context& ctx, float levelDistance) {
  test::AnalyticStack stack = floorStack();
  const CascadeStackImage& image = stack.image;
  GpuStackScene scene(ctx);
  scene.uploadAll(image);
  LightCache cache(ctx);
  const std::vector<gs::GpuLight> lights = {
      test::sunLight(glm::vec3(0.3f, 1.0f, -0.4f), 3.0f),
      test::pointLight(glm::vec3(60.0f, 70.0f, 70.0f), 2000.0f)};
  test::RandomObjects objects;
  objects.addRandom(image, 60, 20.0, 11);
  ObjectSceneSettings settings;
  settings.cardLevelDistance = levelDistance;
  ObjectScene gpu(ctx, settings);
  gpu.update(objects.library, objects.instances, image);
  cache.update(scene, lights, gs::GpuSky{}, {}, image.voxelSize0, &gpu);
  const auto& atLevel = gpu.cardStats().atLevel;
  std::printf("[figures] card light levels 0 / 1 / 2: %u / %u / %u instances\n", atLevel[0],
              atLevel[1], atLevel[2]);
  if (levelDistance > 0.0f)
    for (std::uint32_t l = 0; l < gs::kCardLightLevels; ++l) EXPECT_GT(atLevel[l], 0u) << l;
  else
    EXPECT_EQ(atLevel[0], gpu.cardStats().withCards);

  ObjectSceneCpu cpu(objects.library, objects.instances, image);
  std::vector<std::uint32_t> bases;
  for (const gs::ObjectInstanceGpu& inst : gpu.frame().instances) bases.push_back(inst.info.w);
  cpu.setCards(gpu.cardTable(), gpu.cardTexels(), gpu.downloadCardLight(), bases);

  // Rays from random points towards random instances' centres.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const auto& inst = gpu.frame().instances;
  std::vector<gs::TraceRay> rays;
  for (int r = 0; r < 4000; ++r) {
    const gs::ObjectInstanceGpu& target = inst[std::size_t(r) % inst.size()];
    const glm::vec3 centre = 0.5f * (glm::vec3(target.boundsMin) + glm::vec3(target.boundsMax));
    const glm::vec3 o = centre + 30.0f * glm::vec3(u(rng), u(rng), u(rng));
    const glm::vec3 d = glm::normalize(centre + 2.0f * glm::vec3(u(rng), u(rng), u(rng)) - o);
    gs::TraceRay ray{};
    ray.originTMin = glm::vec4(o, 0.0f);
    ray.dirTMax = glm::vec4(d, 200.0f);
    rays.push_back(ray);
  }
  const auto hits = gpu.trace(rays, false);
  std::size_t objectHits = 0, withCards = 0, texelDiffer = 0, lightDiffer = 0;
  for (std::size_t r = 0; r < rays.size(); ++r) {
    const gs::ObjectTraceHit ref = cpu.traceRegions(rays[r]);
    if (hits[r].normalT.w < 0.0f || ref.normalT.w < 0.0f) continue;
    if (hits[r].instance != ref.instance) continue;  // traversal agreement is tested elsewhere
    ++objectHits;
    withCards += ref.cardTexel != gs::kNoCardLight ? 1 : 0;
    texelDiffer += hits[r].cardTexel != ref.cardTexel ? 1 : 0;
    lightDiffer += hits[r].cardLight != ref.cardLight ? 1 : 0;
  }
  std::printf(
      "[figures] card lookup: %zu object hits, %zu read cards, %zu texel and %zu light "
      "differences against the CPU reference\n",
      objectHits, withCards, texelDiffer, lightDiffer);
  EXPECT_GT(objectHits, 1000u);
  EXPECT_GT(withCards, objectHits * 9 / 10);  // almost every hit finds a card texel
  EXPECT_EQ(texelDiffer, 0u);
  EXPECT_LE(lightDiffer, objectHits / 200);  // rounding where a blend straddles RGB9E5 steps

  // The card light pass itself against card_light.glsl run on the CPU: every texel of every
  // instance, a sun and a point light, shadows from the floor and the other 59 objects.
  const std::vector<std::uint32_t> gpuLight = gpu.downloadCardLight();
  std::size_t texels = 0, lit = 0, differ = 0;
  float worst = 0.0f;
  for (std::uint32_t i = 0; i < inst.size(); ++i) {
    if (inst[i].info.w == gs::kNoCardLight) continue;
    const std::uint32_t base = inst[i].info.w & gs::kCardLightBaseMask;
    const std::vector<std::uint32_t> ref = cpu.cardLight(i, image, lights);
    for (std::size_t t = 0; t < ref.size(); ++t) {
      const glm::vec3 a = gs::unpackRgb9e5(gpuLight.at(base + t));
      const glm::vec3 b = gs::unpackRgb9e5(ref[t]);
      const float scale = std::max({b.x, b.y, b.z, 1e-3f});
      const float d = std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
      worst = std::max(worst, d / scale);
      differ += d > 0.01f * scale ? 1 : 0;
      lit += scale > 1e-3f ? 1 : 0;
      ++texels;
    }
  }
  std::printf(
      "[figures] card light pass vs its CPU reference: %zu texels (%zu lit), %zu differ by "
      "more than 1%%, worst relative difference %.4f\n",
      texels, lit, differ, worst);
  EXPECT_GT(lit, texels / 10);  // many faces look away from both lights or lie in shadow
  // Soft-shadow steps may land either side of an edge in the two compilers' float rounding.
  EXPECT_LE(differ, texels / 200);
}

TEST_F(ObjectCardTest, CardLightAndLookupEqualTheCpuReference) {
  expectCardsEqualTheCpuReference(ctx(), 0.0f);
}

// Objects 20 m around cascade 0's centre with levels every 0.15 of its half extent: the three
// levels' blocks, their texels' choice and the lookup's light index, against the same math on the
// CPU.
TEST_F(ObjectCardTest, CardLightAtLevelsByDistanceEqualsTheCpuReference) {
  expectCardsEqualTheCpuReference(ctx(), 0.15f);
}

TEST_F(ObjectCardTest, AMeshAddedLaterIsCapturedAloneAndTheAtlasEqualsAFreshCapture) {
  test::AnalyticStack stack = floorStack();
  test::RandomObjects objects;
  objects.addRandom(stack.image, 10, 20.0, 3);
  ObjectScene grown(ctx());
  grown.update(objects.library, objects.instances, stack.image);
  objects.library.addBox({2.0f, 1.0f, 3.0f}, {0.1f, 0.2f, 0.9f, 1.0f});
  grown.update(objects.library, objects.instances, stack.image);
  ObjectScene fresh(ctx());
  fresh.update(objects.library, objects.instances, stack.image);
  ASSERT_EQ(grown.cardTable().size(), 3u * 6u);
  EXPECT_EQ(grown.cardMeshTexels(), fresh.cardMeshTexels());
  for (std::size_t k = 0; k < grown.cardTable().size(); ++k) {
    EXPECT_EQ(grown.cardTable()[k].first, fresh.cardTable()[k].first) << k;
    EXPECT_EQ(grown.cardTable()[k].info, fresh.cardTable()[k].info) << k;
  }
  ASSERT_EQ(grown.cardTexels().size(), fresh.cardTexels().size());
  for (std::size_t t = 0; t < grown.cardTexels().size(); ++t)
    EXPECT_EQ(grown.cardTexels()[t].albedo, fresh.cardTexels()[t].albedo) << t;
}

std::vector<gs::ObjectInstanceGpu> instancesOf(std::span<const std::uint32_t> ids,
                                               std::uint32_t mesh, bool moved) {
  std::vector<gs::ObjectInstanceGpu> out;
  for (std::uint32_t id : ids) {
    gs::ObjectInstanceGpu g{};
    g.info = glm::uvec4(mesh, moved ? gs::kObjectFlagMoved : 0u, id, 0u);
    out.push_back(g);
  }
  return out;
}

TEST(CardLightSlots, BlocksPersistAreReusedUnderChurnAndRespectTheCap) {
  CardLightSlots slots;
  const std::uint32_t texels[2] = {100, 40};
  std::vector<std::uint32_t> ids = {1, 2, 3};
  auto frame = instancesOf(ids, 0, false);
  auto relit = slots.assign(frame, texels, false, 1000, 1u << 20);
  EXPECT_EQ(relit.size(), 3u);
  EXPECT_EQ(slots.endTexel(), 300u);
  const std::uint32_t baseOf2 = frame[1].info.w;
  // Churn: every frame one instance of mesh 0 leaves and a new one arrives; the atlas never grows.
  std::uint32_t next = 4;
  for (int f = 0; f < 200; ++f) {
    ids.erase(ids.begin() + (ids[0] == 2 ? 1 : 0));  // keep id 2 forever
    ids.push_back(next++);
    frame = instancesOf(ids, 0, false);
    slots.assign(frame, texels, false, 1000, 1u << 20);
    EXPECT_EQ(slots.endTexel(), 300u);
  }
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] == 2) {
      EXPECT_EQ(frame[i].info.w, baseOf2);  // a kept instance keeps its block
    }
  }
  // The cap: a fourth mesh-0 instance does not fit in 300 texels and gets no cards.
  ids.push_back(next++);
  frame = instancesOf(ids, 0, false);
  slots.assign(frame, texels, false, 1000, 300);
  EXPECT_EQ(frame.back().info.w, gs::kNoCardLight);
  EXPECT_EQ(slots.stats().overBudget, 1u);
  // A mesh without cards never gets a block.
  auto noCards = instancesOf(std::vector<std::uint32_t>{99}, 5, false);
  slots.assign(noCards, texels, false, 1000, 1u << 20);
  EXPECT_EQ(noCards[0].info.w, gs::kNoCardLight);
}

// Over the cap the nearest instances keep cards: moving the viewer evicts the far ones and hands
// their blocks to the now-near ones of the same mesh, without growing past the cap.
TEST(CardLightSlots, OverTheCapTheNearestKeepCards) {
  CardLightSlots slots;
  const std::uint32_t texels[1] = {10};
  std::vector<std::uint32_t> ids(6);
  for (std::uint32_t i = 0; i < 6; ++i) ids[i] = 100 + i;
  auto frame = instancesOf(ids, 0, false);
  for (std::uint32_t i = 0; i < 6; ++i) {  // unit boxes along x at 0, 10, ..., 50
    frame[i].boundsMin = glm::vec4(10.0f * float(i), 0.0f, 0.0f, 1.0f);
    frame[i].boundsMax = glm::vec4(10.0f * float(i) + 1.0f, 1.0f, 1.0f, 1.0f);
  }
  auto withCards = [&] {
    std::vector<std::uint32_t> out;
    for (std::uint32_t i = 0; i < 6; ++i)
      if (frame[i].info.w != gs::kNoCardLight) out.push_back(i);
    return out;
  };
  slots.assign(frame, texels, false, 256, 30, glm::vec3(-5.0f, 0.0f, 0.0f));
  EXPECT_EQ(withCards(), (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(slots.stats().overBudget, 3u);
  slots.assign(frame, texels, false, 256, 30, glm::vec3(55.0f, 0.0f, 0.0f));
  EXPECT_EQ(withCards(), (std::vector<std::uint32_t>{3, 4, 5}));
  EXPECT_EQ(slots.stats().evicted, 3u);
  EXPECT_EQ(slots.endTexel(), 30u);  // the evicted blocks were reused, nothing grew
  // Under the cap nothing is evicted, wherever the viewer is.
  slots.assign(frame, texels, false, 256, 60, glm::vec3(-5.0f, 0.0f, 0.0f));
  EXPECT_EQ(withCards().size(), 6u);
  EXPECT_EQ(slots.stats().evicted, 0u);
}

// Card resolution by distance: unit boxes at 0, 10, ..., 50 along x, the viewer at -5, a level
// every 20: the near two at full resolution, the next two at level 1, the far two at level 2, with
// the level's texels; moving the viewer relevels (a new block, relit first) except within an
// eighth of the band's width beyond its edge, where an instance keeps its level.
TEST(CardLightSlots, LevelsByDistanceSizeBlocksAndHoldNearTheirEdges) {
  CardLightSlots slots;
  const std::uint32_t texels[1] = {64};
  const std::uint32_t levelTexels[gs::kCardLightLevels] = {64, 16, 4};
  CardLightLevels levels;
  levels.texels = levelTexels;
  levels.beyond = 20.0f;
  std::vector<std::uint32_t> ids(6);
  for (std::uint32_t i = 0; i < 6; ++i) ids[i] = 100 + i;
  auto frame = instancesOf(ids, 0, false);
  for (std::uint32_t i = 0; i < 6; ++i) {
    frame[i].boundsMin = glm::vec4(10.0f * float(i), 0.0f, 0.0f, 1.0f);
    frame[i].boundsMax = glm::vec4(10.0f * float(i) + 1.0f, 1.0f, 1.0f, 1.0f);
  }
  auto levelsNow = [&] {
    std::vector<std::uint32_t> out;
    for (const gs::ObjectInstanceGpu& inst : frame)
      out.push_back(inst.info.w >> gs::kCardLightLevelShift);
    return out;
  };
  const std::uint64_t unlimited = ~std::uint64_t(0);
  // Distances to the boxes: 5, 15, 25, 35, 45, 55.
  auto relit = slots.assign(frame, texels, false, 256, 1u << 20, glm::vec3(-5.0f, 0.5f, 0.5f),
                            unlimited, levels);
  EXPECT_EQ(levelsNow(), (std::vector<std::uint32_t>{0, 0, 1, 1, 2, 2}));
  EXPECT_EQ(relit.size(), 6u);
  EXPECT_EQ(slots.stats().liveTexels, 2u * 64u + 2u * 16u + 2u * 4u);
  EXPECT_EQ(slots.endTexel(), 2u * 64u + 2u * 16u + 2u * 4u);
  for (int l = 0; l < 3; ++l) EXPECT_EQ(slots.stats().atLevel[std::size_t(l)], 2u);
  // Viewer 2 further away (distances 7 ... 57): box 1 at 17 and box 3 at 37 stay in their bands,
  // box 2 at 27 too; nothing relevels, nothing new to light.
  relit = slots.assign(frame, texels, false, 256, 1u << 20, glm::vec3(-7.0f, 0.5f, 0.5f), unlimited,
                       levels);
  EXPECT_EQ(slots.stats().relevelled, 0u);
  EXPECT_EQ(relit.size(), 6u);  // every block lit once: the oldest first, all fit the budget
  // Viewer at -9 (distances 9, 19, 29, 39, 49, 59): box 1 (19) and box 3 (39) are within 20 and 40
  // but inside their bands anyway; viewer at -12 (12, 22, 32, 42, 52, 62): box 1 at 22 is within
  // an eighth (2.5) past its band's edge (20) and keeps level 0, box 3 at 42 likewise keeps 1.
  slots.assign(frame, texels, false, 256, 1u << 20, glm::vec3(-12.0f, 0.5f, 0.5f), unlimited,
               levels);
  EXPECT_EQ(levelsNow(), (std::vector<std::uint32_t>{0, 0, 1, 1, 2, 2}));
  EXPECT_EQ(slots.stats().relevelled, 0u);
  // Viewer at -15 (15, 25, 35, 45, ...): box 1 at 25 and box 3 at 45 are past the margins: level
  // 1 and 2, new blocks (box 1 takes the level-1 block box 3 gave back), relit first as never lit
  // (with a budget of one, the first of them).
  relit = slots.assign(frame, texels, false, 1, 1u << 20, glm::vec3(-15.0f, 0.5f, 0.5f), unlimited,
                       levels);
  EXPECT_EQ(levelsNow(), (std::vector<std::uint32_t>{0, 1, 1, 2, 2, 2}));
  EXPECT_EQ(slots.stats().relevelled, 2u);
  EXPECT_EQ(relit, (std::vector<std::uint32_t>{1}));
  // Back: both return to their levels and take blocks back from the free lists.
  const std::uint64_t end = slots.endTexel();
  slots.assign(frame, texels, false, 256, 1u << 20, glm::vec3(-5.0f, 0.5f, 0.5f), unlimited,
               levels);
  EXPECT_EQ(levelsNow(), (std::vector<std::uint32_t>{0, 0, 1, 1, 2, 2}));
  EXPECT_EQ(slots.endTexel(), end);
}

// The per-instance passes run in parallel; what they share (free lists, new blocks) is applied
// after in instance order. So a long run of thousands of instances -- churn, moves, three mesh
// sizes, levels by distance, a cap that evicts, a moving viewer, light changes -- gives the same
// blocks, relight lists and statistics on one thread as on all of them.
TEST(CardLightSlots, ParallelPassesGiveTheSameResultsAsOneThread) {
  const std::uint32_t texels[3] = {64, 24, 0};  // the third mesh has no cards
  const std::uint32_t levelTexels[3 * gs::kCardLightLevels] = {64, 16, 4, 24, 6, 2, 0, 0, 0};
  CardLightLevels levels;
  levels.texels = levelTexels;
  levels.beyond = 30.0f;
  auto run = [&](int threads) {
    tbb::task_arena arena(threads);
    std::vector<std::uint64_t> trace;
    arena.execute([&] {
      CardLightSlots slots;
      std::mt19937 rng(17);
      std::uniform_real_distribution<float> u(-100.0f, 100.0f);
      std::vector<std::uint32_t> ids;
      std::uint32_t next = 0;
      for (int k = 0; k < 7000; ++k) ids.push_back(next++);
      std::vector<glm::vec3> where(200000);
      for (glm::vec3& p : where) p = glm::vec3(u(rng), u(rng) * 0.1f, u(rng));
      for (int f = 0; f < 12; ++f) {
        for (int k = 0; k < 300; ++k) ids.erase(ids.begin() + std::ptrdiff_t(rng() % ids.size()));
        for (int k = 0; k < 300; ++k) ids.push_back(next++);
        std::vector<gs::ObjectInstanceGpu> frame;
        for (std::uint32_t id : ids) {
          gs::ObjectInstanceGpu g{};
          const glm::vec3 p = where[id] + glm::vec3(float(f) * (id % 3 == 0 ? 2.0f : 0.0f));
          g.boundsMin = glm::vec4(p, 1.0f);
          g.boundsMax = glm::vec4(p + 1.0f, 1.0f);
          g.info = glm::uvec4(id % 3, id % 3 == 0 ? gs::kObjectFlagMoved : 0u, id, 0u);
          frame.push_back(g);
        }
        const glm::vec3 viewer(float(f) * 8.0f - 50.0f, 0.0f, 0.0f);
        const std::vector<std::uint32_t> relit =
            slots.assign(frame, texels, f % 5 == 0, 700, 7000 * 4, viewer, 20000, levels);
        for (const gs::ObjectInstanceGpu& g : frame) trace.push_back(g.info.w);
        trace.insert(trace.end(), relit.begin(), relit.end());
        const CardLightSlots::Stats& st = slots.stats();
        trace.insert(trace.end(),
                     {st.relit, st.relitTexels, st.withCards, st.overBudget, st.evicted,
                      st.maxStaleFrames, st.liveTexels, st.relevelled, slots.endTexel()});
      }
    });
    return trace;
  };
  const std::vector<std::uint64_t> one = run(1), all = run(tbb::info::default_concurrency());
  ASSERT_EQ(one.size(), all.size());
  // The last frame's statistics (the trace ends with them): the cap evicts, viewers relevel.
  const std::uint64_t* last = one.data() + one.size() - 9;
  std::printf(
      "[figures] last frame: %llu relit, %llu with cards, %llu over the cap, %llu evicted, "
      "%llu relevelled\n",
      (unsigned long long)last[0], (unsigned long long)last[2], (unsigned long long)last[3],
      (unsigned long long)last[4], (unsigned long long)last[7]);
  EXPECT_GT(last[3], 0u);
  EXPECT_GT(last[4] + last[7], 0u);
  std::size_t differ = 0;
  for (std::size_t k = 0; k < one.size(); ++k) differ += one[k] != all[k] ? 1 : 0;
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(one.size(), 12u * 7000u);
}

TEST(CardLightSlots, MovedAndNeverLitFirstThenTheLongestUnlit) {
  CardLightSlots slots;
  const std::uint32_t texels[1] = {10};
  std::vector<std::uint32_t> ids(10);
  for (std::uint32_t i = 0; i < 10; ++i) ids[i] = i;
  auto frame = instancesOf(ids, 0, false);
  EXPECT_EQ(slots.assign(frame, texels, false, 4, 1u << 20).size(), 4u);  // 0..3, never lit
  EXPECT_EQ(slots.assign(frame, texels, false, 4, 1u << 20),
            (std::vector<std::uint32_t>{4, 5, 6, 7}));
  frame[5].info.y = gs::kObjectFlagMoved;
  // 8 and 9, never lit, come first, then 5 (moved: lit in frame 2, counts as 8 frames older),
  // then the oldest lit (0, lit in frame 1).
  EXPECT_EQ(slots.assign(frame, texels, false, 4, 1u << 20),
            (std::vector<std::uint32_t>{0, 5, 8, 9}));
  EXPECT_LE(slots.stats().maxStaleFrames, 3u);
  // Everything moves every frame: the moves do not starve anyone (round robin by age).
  for (auto& inst : frame) inst.info.y = gs::kObjectFlagMoved;
  for (int f = 0; f < 12; ++f) slots.assign(frame, texels, false, 4, 1u << 20);
  EXPECT_LE(slots.stats().maxStaleFrames, 3u);
  for (auto& inst : frame) inst.info.y = 0;
  // The lights changed: everything is stale again and the budget still bounds the work.
  EXPECT_EQ(slots.assign(frame, texels, true, 4, 1u << 20).size(), 4u);
  // Round robin: with 10 instances and 4 per frame nothing waits more than 3 frames.
  for (int f = 0; f < 12; ++f) slots.assign(frame, texels, false, 4, 1u << 20);
  EXPECT_LE(slots.stats().maxStaleFrames, 3u);
  // The lights change every frame (a moving sun): still round robin, nobody starves.
  for (int f = 0; f < 12; ++f) slots.assign(frame, texels, true, 4, 1u << 20);
  EXPECT_LE(slots.stats().maxStaleFrames, 3u);
  // After one change, the instances lit before it go first, oldest first.
  slots.assign(frame, texels, false, 4, 1u << 20);
  const std::vector<std::uint32_t> first = slots.assign(frame, texels, true, 4, 1u << 20);
  const std::vector<std::uint32_t> second = slots.assign(frame, texels, false, 4, 1u << 20);
  const std::vector<std::uint32_t> third = slots.assign(frame, texels, false, 4, 1u << 20);
  std::vector<std::uint32_t> all(first);
  all.insert(all.end(), second.begin(), second.end());
  all.insert(all.end(), third.begin(), third.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  EXPECT_EQ(all.size(), 10u) << "three frames of 4 relight all 10 after a change";
}

// The relight list is selected per chunk of instances in parallel: across thousands of
// instances (several chunks) it is still exactly the smallest keys, ties to the lower index.
TEST(CardLightSlots, TheRelightListAcrossManyInstancesIsTheSmallestKeys) {
  CardLightSlots slots;
  const std::uint32_t texels[1] = {10};
  const std::uint32_t n = 9000;
  std::vector<std::uint32_t> ids(n);
  for (std::uint32_t i = 0; i < n; ++i) ids[i] = i;
  auto frame = instancesOf(ids, 0, false);
  EXPECT_EQ(slots.assign(frame, texels, false, n, 1u << 30).size(), n);  // all lit in frame 1
  // Frame 2: every 37th moved (key 1 - 8), the rest lit in frame 1 (key 1); the budget takes
  // the moved first, the lowest indices first when it cannot take them all.
  std::vector<std::uint32_t> moved;
  for (std::uint32_t i = 0; i < n; i += 37) {
    frame[i].info.y = gs::kObjectFlagMoved;
    moved.push_back(i);
  }
  const std::vector<std::uint32_t> some =
      slots.assign(frame, texels, false, std::uint32_t(moved.size() / 2), 1u << 30);
  EXPECT_EQ(some, std::vector<std::uint32_t>(moved.begin(), moved.begin() + moved.size() / 2));
  // Frame 3: the moved ones lit in frame 2 now have key 2 - 8; those not taken, 1 - 8, go first,
  // then the first moved of frame 2, then (key 1) the lowest indices of the rest.
  const std::uint32_t budget = std::uint32_t(moved.size()) + 5;
  const std::vector<std::uint32_t> next = slots.assign(frame, texels, false, budget, 1u << 30);
  std::vector<std::uint32_t> expected(moved.begin(), moved.end());
  for (std::uint32_t i = 0, extra = 0; extra < 5; ++i)
    if (i % 37 != 0) expected.push_back(i), ++extra;
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(next, expected);
  EXPECT_EQ(slots.stats().maxStaleFrames, 2u);  // the unmoved ones lit in frame 1, now frame 3
}

// The texel budget: the relight list stops before the texels exceed it, a mesh larger than the
// budget is still relit (alone), and under lights that change every frame every instance still
// comes round (oldest first).
TEST(CardLightSlots, ATexelBudgetBoundsTheWorkButRelightsAtLeastOne) {
  CardLightSlots slots;
  const std::uint32_t texels[2] = {10, 100};  // mesh 0 small, mesh 1 larger than the budget
  const std::uint32_t smallIds[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  const std::uint32_t largeIds[2] = {8, 9};
  auto frame = instancesOf(smallIds, 0, false);
  const auto large = instancesOf(largeIds, 1, false);
  frame.insert(frame.end(), large.begin(), large.end());
  constexpr std::uint64_t kTexelBudget = 50, kCap = 1u << 20;
  // Never lit, index order: five small instances fill the 50 texels.
  EXPECT_EQ(slots.assign(frame, texels, false, 100, kCap, {}, kTexelBudget),
            (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(slots.stats().relitTexels, 50u);
  // Then 5..7 (30 texels); the large 8 would exceed the budget after them.
  EXPECT_EQ(slots.assign(frame, texels, false, 100, kCap, {}, kTexelBudget),
            (std::vector<std::uint32_t>{5, 6, 7}));
  // The large instances come first now (never lit) and go one a frame, alone.
  EXPECT_EQ(slots.assign(frame, texels, false, 100, kCap, {}, kTexelBudget),
            (std::vector<std::uint32_t>{8}));
  EXPECT_EQ(slots.stats().relitTexels, 100u);
  EXPECT_EQ(slots.assign(frame, texels, false, 100, kCap, {}, kTexelBudget),
            (std::vector<std::uint32_t>{9}));
  // A moving sun: 280 texels at 50 (or one large instance) a frame; everyone comes round.
  std::vector<int> lastLit(frame.size(), -1);
  for (int f = 0; f < 40; ++f)
    for (std::uint32_t i : slots.assign(frame, texels, true, 100, kCap, {}, kTexelBudget)) {
      lastLit[i] = f;
      EXPECT_TRUE(slots.stats().relitTexels <= kTexelBudget || slots.stats().relit == 1u);
    }
  for (std::size_t i = 0; i < lastLit.size(); ++i) EXPECT_GE(lastLit[i], 30) << "instance " << i;
  EXPECT_LE(slots.stats().maxStaleFrames, 10u);
}

}  // namespace
}  // namespace sdfstream
