// The whole streamed path on a real pack: bunny OBJ → 4-LOD pack → PackTileStore → TileLoader →
// CascadeStack → stack traversal. GPU vs CPU reference of the same math, vs Embree on the source
// triangles, and the fall-back to coarser cascades where pages are missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "bench/gpu_clock_warmup.h"
#include "core/stats.h"
#include "gi/camera.h"
#include "gi/gpu_stack_tracer.h"
#include "reference/embree_scene.h"
#include "streaming/pack_store.h"
#include "tests/support/gpu_test.h"
#include "tests/support/streamed_bunny.h"
#include "tests/support/test_data.h"
#include "tests/trace/trace_fixture.h"
#include "world/pack_import.h"

namespace sdfstream {
namespace {

using test::streamBunny;
using test::StreamedBunny;

std::vector<gpu_shared::TraceRay> raysFromCamera(const StreamedBunny& b,
                                                 const CascadeStackImage& img, int count) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  glm::dvec3 lo(b.triangles.boundsMin()), hi(b.triangles.boundsMax());
  std::vector<gpu_shared::TraceRay> rays(count);
  for (auto& r : rays) {
    glm::dvec3 target = lo + (hi - lo) * glm::dvec3(u(rng), u(rng), u(rng));
    r.originTMin = glm::vec4(img.toStack(b.camera), 0.0f);
    r.dirTMax = glm::vec4(glm::vec3(glm::normalize(target - b.camera)), 1e30f);
  }
  return rays;
}

// A ray that runs exactly along a page face, heading out through it (a camera on a page boundary
// looking along it: every pixel of the centre column), sits on the face of the page floor() gives
// and must be traced in the page beyond. Rays from points on cascade-0 page faces (x, and x and
// y, multiples of 8 voxels) towards the camera's hits on the bunny, moved onto the face plane,
// with the crossing components a hair negative (onFace), and the same rays started a thousandth
// of a voxel inside the page beyond (beside).
struct FaceRays {
  std::vector<gpu_shared::TraceRay> onFace, beside;
};

FaceRays raysAlongPageFaces(const StreamedBunny& b, const CascadeStackImage& img) {
  auto cameraRays = raysFromCamera(b, img, 2000);
  auto cameraHits = traceStackCpu(img, cameraRays, TraceSettings{});
  FaceRays out;
  for (size_t i = 0; i < cameraRays.size(); ++i) {
    if (!(cameraHits[i].flags & gpu_shared::kHitFlagHit)) continue;
    if ((cameraHits[i].flags >> gpu_shared::kHitCascadeShift) & 15) continue;  // cascade 0 only
    const glm::vec3 hit = glm::vec3(cameraRays[i].originTMin) +
                          glm::vec3(cameraRays[i].dirTMax) * cameraHits[i].normalT.w;
    const bool both = out.onFace.size() % 2 == 1;  // every other ray on an x and a y face
    glm::vec3 from = glm::vec3(cameraRays[i].originTMin);
    from.x = 8.0f * std::round(hit.x / 8.0f);
    if (both) from.y = 8.0f * std::round(hit.y / 8.0f);
    glm::vec3 to = hit;
    to.x = from.x;
    if (both) to.y = from.y;
    glm::vec3 dir = to - from;
    if (glm::length(dir) < 8.0f) continue;
    dir = glm::normalize(dir);
    dir.x = -1e-6f;
    if (both) dir.y = -1e-6f;
    gpu_shared::TraceRay r{};
    r.originTMin = glm::vec4(from, 0.0f);
    r.dirTMax = glm::vec4(dir, 1e30f);
    out.onFace.push_back(r);
    r.originTMin = glm::vec4(from - glm::vec3(1e-3f, both ? 1e-3f : 0.0f, 0.0f), 0.0f);
    out.beside.push_back(r);
  }
  return out;
}

class StackTrace : public test::GpuTest {};

// A GPU tracer of the streamed stack with every atlas slot uploaded.
std::unique_ptr<GpuStackTracer> tracerWithEverySlot(gpu::Context& ctx, const StreamedBunny& b) {
  auto tracer = std::make_unique<GpuStackTracer>(ctx, *b.stack);
  std::vector<std::uint32_t> all(b.stack->options().atlasSlots);
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  tracer->sync(*b.stack, all);
  return tracer;
}

TEST_F(StackTrace, GpuMatchesCpuAndEmbreeThroughStreamedCascades) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  auto rays = raysFromCamera(b, img, 8000);
  TraceSettings settings;
  auto cpu = traceStackCpu(img, rays, settings);

  GpuStackTracer gpuTracer(ctx(), *b.stack);
  gpuTracer.sync(*b.stack, b.stack->takeDirtySlots());
  // Everything resident was written by the settle above, so upload all used slots too.
  std::vector<std::uint32_t> all(b.stack->options().atlasSlots);
  for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
  gpuTracer.sync(*b.stack, all);
  auto gpu = gpuTracer.trace(rays, settings);

  int mismatched = 0, hits = 0, beyond = 0;
  int perCascade[8] = {};
  for (size_t i = 0; i < rays.size(); ++i) {
    if (gpu[i].flags != cpu[i].flags) {
      ++mismatched;
      continue;
    }
    if (!(cpu[i].flags & gpu_shared::kHitFlagHit)) continue;
    ++hits;
    ++perCascade[(cpu[i].flags >> gpu_shared::kHitCascadeShift) & 15];
    if (std::abs(gpu[i].normalT.w - cpu[i].normalT.w) > 1e-3f) ++beyond;
  }
  std::printf(
      "[figures] stack GPU vs CPU: %zu rays, %d hits (per cascade %d/%d/%d), %d flag "
      "mismatches, %d beyond 1e-3 voxel\n",
      rays.size(), hits, perCascade[0], perCascade[1], perCascade[2], mismatched, beyond);
  EXPECT_EQ(mismatched, 0);
  EXPECT_EQ(beyond, 0);
  EXPECT_GT(hits, 3000);
  EXPECT_GT(perCascade[1] + perCascade[2], 100) << "rays must cross into coarser cascades";

  // Against Embree on the source triangles, in units of the hit cascade's voxel.
  EmbreeScene embree(b.triangles);
  std::vector<double> dt;
  int agree = 0, considered = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    glm::vec3 dir(rays[i].dirTMax);
    auto ref = embree.intersect(glm::vec3(b.camera), dir, 0.0f, 1e30f);
    if (ref && std::abs(glm::dot(ref->normal, dir)) < 0.2f) continue;  // grazing
    ++considered;
    bool ours = cpu[i].flags & gpu_shared::kHitFlagHit;
    agree += ours == bool(ref);
    if (ours && ref) {
      double scale = double(1 << ((cpu[i].flags >> gpu_shared::kHitCascadeShift) & 15));
      dt.push_back(std::abs(cpu[i].normalT.w * img.voxelSize0 - ref->t) / (img.voxelSize0 * scale));
    }
  }
  std::sort(dt.begin(), dt.end());
  double median = dt[dt.size() / 2];
  std::printf(
      "[figures] stack vs Embree: agreement %.3f%% of %d non-grazing rays, median |dt| "
      "%.3f hit-cascade voxels, p90 %.3f\n",
      100.0 * agree / considered, considered, median, dt[dt.size() * 9 / 10]);
  EXPECT_GE(double(agree) / considered, 0.98);
  EXPECT_LE(median, 0.5);
}

// The GPU takes the same page along a face as the CPU reference.
TEST_F(StackTrace, GpuRaysAlongAPageFaceMatchTheCpu) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  const FaceRays rays = raysAlongPageFaces(b, img);
  ASSERT_GT(rays.onFace.size(), 200u);
  auto cpu = traceStackCpu(img, rays.onFace, TraceSettings{});
  const auto tracer = tracerWithEverySlot(ctx(), b);
  GpuStackTracer& gpuTracer = *tracer;
  auto gpu = gpuTracer.trace(rays.onFace, TraceSettings{});
  int mismatched = 0, hits = 0;
  for (size_t i = 0; i < rays.onFace.size(); ++i) {
    hits += cpu[i].flags & gpu_shared::kHitFlagHit;
    if (gpu[i].flags != cpu[i].flags || std::abs(gpu[i].normalT.w - cpu[i].normalT.w) > 1e-3f)
      ++mismatched;
  }
  std::printf("[figures] %zu rays along page faces, GPU vs CPU: %d hits, %d differ\n",
              rays.onFace.size(), hits, mismatched);
  EXPECT_EQ(mismatched, 0);
  EXPECT_GT(hits, int(rays.onFace.size()) / 2);
}

// Benchmarks time the pass as several dispatches back to back: each one timed, the same hits.
TEST_F(StackTrace, BackToBackDispatchesReturnTheSameHits) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  auto rays = raysFromCamera(b, img, 2000);
  const auto tracer = tracerWithEverySlot(ctx(), b);
  GpuStackTracer& gpuTracer = *tracer;
  const auto once = gpuTracer.trace(rays, TraceSettings{});
  const auto thrice = gpuTracer.trace(rays, TraceSettings{}, 3);
  int timed = 0;
  for (const gpu::PassTiming& t : gpuTracer.lastTimings()) timed += t.name == "trace_stack";
  EXPECT_EQ(timed, 3);
  ASSERT_EQ(once.size(), thrice.size());
  int differ = 0, hits = 0;
  for (std::size_t i = 0; i < once.size(); ++i) {
    hits += (once[i].flags & gpu_shared::kHitFlagHit) != 0;
    differ += once[i].flags != thrice[i].flags || once[i].normalT != thrice[i].normalT ||
              once[i].steps != thrice[i].steps;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(hits, 500);
  EXPECT_THROW(gpuTracer.trace(rays, TraceSettings{}, 0), std::invalid_argument);
  EXPECT_THROW(gpuTracer.trace(rays, TraceSettings{}, 61), std::invalid_argument);
}

// The real-GPU table's clock warm-up (bench/gpu_clock_warmup.h): batches of the same traversal
// until two agree, then the last batch is the timing; it keeps going at least minSeconds.
TEST_F(StackTrace, ClockWarmupRunsUntilTwoBatchesAgree) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  auto rays = raysFromCamera(b, img, 2000);
  const auto tracer = tracerWithEverySlot(ctx(), b);
  GpuStackTracer& gpuTracer = *tracer;
  bench::GpuClockWarmup warmup(gpuTracer, rays, 5.0);
  const bench::GpuClockWarmup::Result r = warmup.run(0.3, 20.0, 0.5);
  std::printf("[figures] warm-up: %d batches, %.2f s, a dispatch %.3f -> %.3f ms, last batch %zu\n",
              r.batches, r.seconds, r.firstMs, r.lastMs, warmup.lastBatch().size());
  EXPECT_GE(r.batches, 2);
  EXPECT_GE(r.seconds, 0.3);
  EXPECT_TRUE(r.settled) << "lavapipe's dispatches of one traversal agree within 50%";
  ASSERT_FALSE(warmup.lastBatch().empty());
  EXPECT_GT(r.lastMs, 0.0);
  EXPECT_DOUBLE_EQ(r.lastMs, median(warmup.lastBatch()));
  bench::GpuClockWarmup nothing(gpuTracer, {});
  EXPECT_EQ(nothing.run(0.1).batches, 0);
}

TEST(StackTraceCpu, MissingPagesFallBackToACoarserCascade) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  auto rays = raysFromCamera(b, img, 2000);
  auto before = traceStackCpu(img, rays, TraceSettings{});
  // Pretend cascade 0 has not streamed in at all.
  std::fill(img.pageTables.begin(), img.pageTables.begin() + layout::kCascadePageCount,
            layout::kPageMissing);
  auto after = traceStackCpu(img, rays, TraceSettings{});
  int hitsBefore = 0, hitsAfter = 0, fellBack = 0, inCascade0 = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    hitsBefore += before[i].flags & gpu_shared::kHitFlagHit;
    hitsAfter += after[i].flags & gpu_shared::kHitFlagHit;
    fellBack += (after[i].flags & gpu_shared::kHitFlagFellBack) ? 1 : 0;
    if ((after[i].flags & gpu_shared::kHitFlagHit) &&
        ((after[i].flags >> gpu_shared::kHitCascadeShift) & 15) == 0)
      ++inCascade0;
  }
  EXPECT_EQ(inCascade0, 0);
  EXPECT_GT(fellBack, 1000);
  EXPECT_GE(hitsAfter, hitsBefore * 95 / 100) << "coarser cascades still see the bunny";
}

// Sampling's visibility tests trace by a looser rule (sdfVisibilitySteps: over-relaxed steps, a
// hit threshold of up to a quarter voxel away from the target). Probe-to-receiver segments like
// sampling's: from points around the bunny to the camera's hits on it, lifted one voxel off the
// surface. The loose rule must never see through a wall the exact trace finds before the
// target (within half a voxel of it a hit is the receiver's own surface), may block only
// where the ray passes within its threshold of a surface (the exact trace with that threshold
// blocks too), and must take fewer steps.
TEST(StackTraceCpu, VisibilityRuleBlocksWhatTheExactTraceBlocksInFewerSteps) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  auto cameraRays = raysFromCamera(b, img, 6000);
  auto cameraHits = traceStackCpu(img, cameraRays, TraceSettings{});
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const glm::vec3 lo = img.toStack(glm::dvec3(b.triangles.boundsMin()));
  const glm::vec3 hi = img.toStack(glm::dvec3(b.triangles.boundsMax()));
  const glm::vec3 grow = (hi - lo) * 0.25f;
  std::vector<gpu_shared::TraceRay> tests;
  for (size_t i = 0; i < cameraRays.size(); ++i) {
    if (!(cameraHits[i].flags & gpu_shared::kHitFlagHit)) continue;
    const float scale = float(1 << ((cameraHits[i].flags >> gpu_shared::kHitCascadeShift) & 15));
    const glm::vec3 hit = glm::vec3(cameraRays[i].originTMin) +
                          glm::vec3(cameraRays[i].dirTMax) * cameraHits[i].normalT.w;
    const glm::vec3 receiver = hit + glm::vec3(cameraHits[i].normalT) * scale;
    const glm::vec3 probe = lo - grow + (hi - lo + 2.0f * grow) * glm::vec3(u(rng), u(rng), u(rng));
    const glm::vec3 d = receiver - probe;
    const float r = glm::length(d);
    if (r < 1.0f) continue;
    tests.push_back({glm::vec4(probe, 0.0f), glm::vec4(d / r, r)});
  }
  TraceSettings exact, loose, thick;
  loose.visibilityRule = true;
  thick.hitEpsilon = 0.3f;  // the rule's largest threshold (0.25) and a margin
  const auto e = traceStackCpu(img, tests, exact);
  const auto l = traceStackCpu(img, tests, loose);
  const auto t = traceStackCpu(img, tests, thick);
  auto blocked = [](const gpu_shared::TraceHit& h) {
    return (h.flags & gpu_shared::kHitFlagHit) != 0u;
  };
  int exactBlocked = 0, looseBlocked = 0, seenThrough = 0, blockedBeyondThreshold = 0;
  double exactSteps = 0.0, looseSteps = 0.0;
  for (size_t i = 0; i < tests.size(); ++i) {
    exactBlocked += blocked(e[i]);
    looseBlocked += blocked(l[i]);
    // A hit within half a voxel of the target is the receiver's own surface (either answer
    // will do); one before it is a wall the loose rule must see too.
    const float scale = float(1 << ((e[i].flags >> gpu_shared::kHitCascadeShift) & 15));
    const bool wallBefore = blocked(e[i]) && e[i].normalT.w < tests[i].dirTMax.w - 0.5f * scale;
    seenThrough += wallBefore && !blocked(l[i]);
    blockedBeyondThreshold += blocked(l[i]) && !blocked(t[i]);
    exactSteps += e[i].steps;
    looseSteps += l[i].steps;
  }
  const double n = double(tests.size());
  std::printf(
      "[figures] visibility rule: %zu segments, blocked exact %d / loose %d; seen through "
      "%d, blocked beyond 0.3 voxel %d; steps a test exact %.2f, loose %.2f\n",
      tests.size(), exactBlocked, looseBlocked, seenThrough, blockedBeyondThreshold, exactSteps / n,
      looseSteps / n);
  ASSERT_GT(tests.size(), 3000u);
  EXPECT_GT(exactBlocked, int(n * 0.1));
  EXPECT_LT(exactBlocked, int(n * 0.9));
  EXPECT_EQ(seenThrough, 0);
  EXPECT_EQ(blockedBeyondThreshold, 0);
  EXPECT_LT(looseBlocked - exactBlocked, int(n * 0.05));
  EXPECT_LT(looseSteps, 0.9 * exactSteps);
}

// The CPU reference's count of steps by kind covers every step the rays took, and the bunny's
// camera rays take steps of each kind but the missing page's (every page is streamed in).
TEST(StackTraceCpu, StepKindsAddUpToTheSteps) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  const auto rays = raysFromCamera(b, img, 2000);
  TraceStepKinds kinds;
  const auto hits = traceStackCpu(img, rays, TraceSettings{}, &kinds);
  std::uint64_t steps = 0, counted = 0;
  for (const auto& h : hits) steps += h.steps;
  for (std::uint64_t k : kinds.steps) counted += k;
  std::printf(
      "[figures] steps by kind: near surface %llu, band %llu, clamped %llu, empty page "
      "%llu, missing page %llu of %llu\n",
      (unsigned long long)kinds.steps[0], (unsigned long long)kinds.steps[1],
      (unsigned long long)kinds.steps[2], (unsigned long long)kinds.steps[3],
      (unsigned long long)kinds.steps[4], (unsigned long long)steps);
  EXPECT_EQ(counted, steps);
  EXPECT_GT(kinds.steps[0], 0u);
  EXPECT_GT(kinds.steps[1], 0u);
  EXPECT_GT(kinds.steps[2], 0u);
  EXPECT_GT(kinds.steps[3], 0u);
  EXPECT_EQ(kinds.steps[4], 0u);
}

// The same pack seen 100 km away: tile and brick coordinates shifted by a whole number of tiles.
class ShiftedStore : public TileStore {
 public:
  ShiftedStore(const TileStore& base, glm::ivec3 shift) : base_(base), shift_(shift) {}
  const PartitionSpec& spec() const override { return base_.spec(); }
  bool hasTile(glm::ivec3 t) const override { return base_.hasTile(t - shift_); }
  std::shared_ptr<const Tile> load(glm::ivec3 t, int lod, std::size_t* bytesRead) const override {
    auto src = base_.load(t - shift_, lod, bytesRead);
    if (!src) return nullptr;
    auto tile = std::make_shared<Tile>(*src);
    tile->coord = t;
    for (int l = 0; l < int(tile->lods.size()); ++l)
      for (Brick& b : tile->lods[l].bricks) b.coord += shift_ * spec().tileBricks(l);
    return tile;
  }

 private:
  const TileStore& base_;
  glm::ivec3 shift_;
};

// The rays along the faces hit what the rays beside them hit (CPU reference).
TEST(StackTraceCpu, RaysAlongAPageFaceHitWhatRaysBesideItHit) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  const FaceRays rays = raysAlongPageFaces(b, img);
  ASSERT_GT(rays.onFace.size(), 200u);
  auto faceHits = traceStackCpu(img, rays.onFace, TraceSettings{});
  auto besideHits = traceStackCpu(img, rays.beside, TraceSettings{});
  int differ = 0, hits = 0, outOfSteps = 0;
  for (size_t i = 0; i < rays.onFace.size(); ++i) {
    const bool a = faceHits[i].flags & gpu_shared::kHitFlagHit;
    const bool c = besideHits[i].flags & gpu_shared::kHitFlagHit;
    hits += a;
    outOfSteps += (faceHits[i].flags & gpu_shared::kHitFlagRanOutOfSteps) ? 1 : 0;
    if (a != c || (a && std::abs(faceHits[i].normalT.w - besideHits[i].normalT.w) > 0.05f))
      ++differ;
  }
  std::printf(
      "[figures] %zu rays along page faces: %d hits, %d out of steps, %d differ from the "
      "rays beside them\n",
      rays.onFace.size(), hits, outOfSteps, differ);
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(outOfSteps, 0);
  EXPECT_GT(hits, int(rays.onFace.size()) / 2);
}

// Camera rays (sdfTraceStack, TraceSettings::descend) from a camera outside cascade 0's window:
// they switch to cascade 0 where they enter its window and hit the bunny's fine surface; rays
// that stay in the cascade they start in (as probe rays do) hit cascade 1's, which the LOD
// chain's min-filter dilates. Against Embree on the source triangles, in cascade-0 voxels, for the
// rays whose surface lies inside cascade 0's window.
TEST(StackTraceCpu, CameraRaysFromOutsideCascadeZeroDescendToItsSurface) {
  StreamedBunny b = streamBunny();
  CascadeStackImage img = b.stack->stackImage();
  // 1.2 cascade-0 half-windows behind the streaming camera: outside cascade 0, inside cascade 1.
  const glm::dvec3 toward = glm::normalize(b.camera - glm::dvec3(0.0, 0.1, 0.0));
  const glm::dvec3 camera = b.camera + toward * (1.2 * 64.0 * img.voxelSize0);
  const glm::vec3 origin = img.toStack(camera);
  const gpu_shared::CascadeTraceParams& c0 = img.params[0];
  const glm::vec3 in0 = (origin - glm::vec3(c0.offsetScale)) / c0.offsetScale.w;
  ASSERT_TRUE(glm::any(glm::lessThan(in0, glm::vec3(0.0f))) ||
              glm::any(glm::greaterThan(in0, glm::vec3(128.0f))));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const glm::dvec3 lo(b.triangles.boundsMin()), hi(b.triangles.boundsMax());
  std::vector<gpu_shared::TraceRay> rays(6000);
  for (auto& r : rays) {
    const glm::dvec3 target = lo + (hi - lo) * glm::dvec3(u(rng), u(rng), u(rng));
    r.originTMin = glm::vec4(origin, 0.0f);
    r.dirTMax = glm::vec4(glm::vec3(glm::normalize(target - camera)), 1e30f);
  }
  TraceSettings descending;
  descending.descend = true;
  const auto fine = traceStackCpu(img, rays, descending);
  const auto coarse = traceStackCpu(img, rays, TraceSettings{});
  EmbreeScene embree(b.triangles);
  std::vector<double> dtFine, dtCoarse;
  int considered = 0, agreeFine = 0, fineInCascade0 = 0, coarseInCascade0 = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const glm::vec3 dir(rays[i].dirTMax);
    const auto ref = embree.intersect(glm::vec3(camera), dir, 0.0f, 1e30f);
    if (!ref || std::abs(glm::dot(ref->normal, dir)) < 0.2f) continue;  // a miss or grazing
    // Only surfaces well inside cascade 0's window (most of the bunny lies in cascade 1's).
    const glm::vec3 at =
        (origin + dir * float(ref->t / img.voxelSize0) - glm::vec3(c0.offsetScale)) /
        c0.offsetScale.w;
    if (glm::any(glm::lessThan(at, glm::vec3(4.0f))) ||
        glm::any(glm::greaterThan(at, glm::vec3(124.0f))))
      continue;
    ++considered;
    const bool f = fine[i].flags & gpu_shared::kHitFlagHit;
    const bool c = coarse[i].flags & gpu_shared::kHitFlagHit;
    agreeFine += f == bool(ref);
    fineInCascade0 += f && ((fine[i].flags >> gpu_shared::kHitCascadeShift) & 15) == 0;
    coarseInCascade0 += c && ((coarse[i].flags >> gpu_shared::kHitCascadeShift) & 15) == 0;
    if (ref && f)
      dtFine.push_back(std::abs(fine[i].normalT.w * img.voxelSize0 - ref->t) / img.voxelSize0);
    if (ref && c)
      dtCoarse.push_back(std::abs(coarse[i].normalT.w * img.voxelSize0 - ref->t) / img.voxelSize0);
  }
  ASSERT_GT(dtFine.size(), 200u);
  ASSERT_GT(dtCoarse.size(), 200u);
  std::sort(dtFine.begin(), dtFine.end());
  std::sort(dtCoarse.begin(), dtCoarse.end());
  const double medianFine = dtFine[dtFine.size() / 2], medianCoarse = dtCoarse[dtCoarse.size() / 2];
  std::printf(
      "[figures] camera outside cascade 0: %d non-grazing rays, descending: %d hits in "
      "cascade 0, agreement %.3f, median |dt| %.3f voxels (p90 %.3f); staying: %d in "
      "cascade 0, median |dt| %.3f (p90 %.3f)\n",
      considered, fineInCascade0, double(agreeFine) / considered, medianFine,
      dtFine[dtFine.size() * 9 / 10], coarseInCascade0, medianCoarse,
      dtCoarse[dtCoarse.size() * 9 / 10]);
  EXPECT_EQ(coarseInCascade0, 0);
  EXPECT_GT(fineInCascade0, int(dtFine.size()) * 9 / 10);
  EXPECT_GE(double(agreeFine) / considered, 0.98);
  EXPECT_LE(medianFine, 0.5);
  EXPECT_LT(medianFine, 0.5 * medianCoarse);
}

TEST(StackTraceCpu, HundredKilometresFromTheOriginRendersIdentically) {
  StreamedBunny b = streamBunny();
  const PartitionSpec& spec = b.store->spec();
  const int k = int(std::ceil(100000.0 / spec.tileSizeMeters()));
  glm::ivec3 shift(k, 0, -k);
  ShiftedStore far(*b.store, shift);
  TileLoader farLoader(far);
  StreamingOptions so;
  so.cascades = 3;
  CascadeStack farStack(far, farLoader, so);
  glm::dvec3 farCamera = b.camera + glm::dvec3(shift) * spec.tileSizeMeters();
  ASSERT_GT(glm::length(farCamera), 100000.0 * 1.4);
  for (int i = 0; i < 100 && !farStack.settled(); ++i) {
    farStack.update(farCamera);
    farLoader.waitIdle();
  }
  ASSERT_TRUE(farStack.settled());
  CascadeStackImage nearImg = b.stack->stackImage(), farImg = farStack.stackImage();
  Camera nearCam{b.camera, glm::dvec3(0.0, 0.1, 0.0), glm::dvec3(0, 1, 0), 50.0};
  Camera farCam{farCamera, nearCam.target + glm::dvec3(shift) * spec.tileSizeMeters(),
                glm::dvec3(0, 1, 0), 50.0};
  auto nearRays = primaryRaysFrom(nearCam, 96, 64, nearImg.toStack(nearCam.position));
  auto farRays = primaryRaysFrom(farCam, 96, 64, farImg.toStack(farCam.position));
  auto nearHits = traceStackCpu(nearImg, nearRays, TraceSettings{});
  auto farHits = traceStackCpu(farImg, farRays, TraceSettings{});
  // The camera's world-space direction (target − position) is computed in double at both
  // places, so a ray direction can differ in its last float bit; everything downstream is
  // cascade-relative. Require the same hits to float precision and almost all bit-identical.
  int hits = 0, bitIdentical = 0;
  for (size_t i = 0; i < nearHits.size(); ++i) {
    ASSERT_EQ(nearHits[i].flags, farHits[i].flags) << i;
    ASSERT_EQ(nearHits[i].albedo, farHits[i].albedo) << i;
    ASSERT_NEAR(nearHits[i].normalT.w, farHits[i].normalT.w, 1e-4f) << i;
    const bool hit = nearHits[i].flags & gpu_shared::kHitFlagHit;
    if (hit) {
      ASSERT_GT(glm::dot(glm::vec3(nearHits[i].normalT), glm::vec3(farHits[i].normalT)), 0.9999f)
          << i;
    }
    hits += hit;
    bitIdentical += nearHits[i].normalT == farHits[i].normalT;
  }
  std::printf("[figures] 100 km from the origin: %d hits, %d of %zu rays bit-identical\n", hits,
              bitIdentical, nearHits.size());
  EXPECT_GT(hits, 1000);
  EXPECT_GE(bitIdentical, int(nearHits.size() * 999 / 1000));
}

}  // namespace
}  // namespace sdfstream
