// Moving objects bounce the light they receive (cards): a saturated red box (albedo 0.8, 0.1,
// 0.1) resting on a white floor in sunlight, sky off. The floor's indirect irradiance beside the
// box's sunlit face, from the GI (probes, with the box a moving object) against the path tracer
// on the same triangles and lights (NoDirectLights: everything but the sun's direct term), with
// cards on and off. Off, object hits carry no direct light, so the red bounce goes missing.
// The same box arriving by sliding (within the bound a few frames after it stops), and an
// emissive box hovering in the dark, whose light the floor under it receives through the probes.
#include <cmath>
#include <cstdio>
#include <functional>

#include <gtest/gtest.h>

#include "gi/gi_system.h"
#include "objects/primitive_meshes.h"
#include "reference/path_tracer.h"
#include "tests/lights/light_scenes.h"
#include "tests/support/analytic_stack.h"
#include "tests/support/gpu_test.h"
#include "world/color_pack.h"

namespace sdfstream {
namespace {
namespace gs = gpu_shared;
using reference::IrradianceEstimate;
using reference::IrradianceKind;
using reference::PathTracer;

class ObjectCardBounce : public test::GpuTest {};

constexpr glm::vec4 kRed(0.8f, 0.1f, 0.1f, 1.0f);
constexpr float kFloorTop = 40.0f;

// A cube of half-edge `half` m at the window's centre, `lift` m above the floor (1 m voxels,
// probes every 8 m). Receivers on the floor at 1/8, 3/8, 5/8 and 7/8 of the edge from the sunlit
// face (sunlit boxes) or on a 4 × 4 grid under the box (emissive boxes, in the dark).
struct BoxSetup {
  float half = 16.0f;
  glm::vec4 albedo = kRed;
  glm::vec3 emission{0.0f};
  float lift = 0.0f;
  float halfHeight = 0.0f;  // 0: a cube; else a slab this many m thick
  bool emissive() const { return emission != glm::vec3(0.0f); }
  glm::vec3 halfExtents() const { return {half, halfHeight > 0.0f ? halfHeight : half, half}; }
  glm::dvec3 centre() const { return {64.0, kFloorTop + lift + halfExtents().y, 64.0}; }
};

SceneLights lightsFor(const BoxSetup& b) {
  SceneLights lights;
  lights.sky.zenith = lights.sky.horizon = glm::vec3(0.0f);
  if (b.emissive()) return lights;  // the box is the only light
  SceneLight sun;
  sun.direction = -glm::normalize(glm::vec3(1.0f, 1.2f, 0.3f));  // lights the +x face
  sun.intensity = 3.0f;
  sun.shadowSharpness = 0.0f;  // hard, as the path tracer's
  lights.lights.push_back(sun);
  return lights;
}

// The floor (1 m voxels, the stack window's 128 m) and the box as triangles, world = stack.
TriangleScene referenceScene(const BoxSetup& b) {
  TriangleScene s;
  s.materials.resize(2);
  s.materials[0].baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  s.materials[1].baseColorFactor = b.albedo;
  s.materials[1].emissive = b.emission;
  s.positions = {
      {0, kFloorTop, 0}, {128, kFloorTop, 0}, {128, kFloorTop, 128}, {0, kFloorTop, 128}};
  s.triangles = {{0, 2, 1}, {0, 3, 2}};
  s.triangleMaterial = {0, 0};
  const TriangleScene box = makeBoxMesh(b.halfExtents(), b.albedo, b.emission);
  const std::uint32_t base = std::uint32_t(s.positions.size());
  for (const glm::vec3& p : box.positions) s.positions.push_back(p + glm::vec3(b.centre()));
  for (const glm::uvec3& t : box.triangles) {
    s.triangles.push_back(t + base);
    s.triangleMaterial.push_back(1);
  }
  s.uvs.assign(s.positions.size(), glm::vec2(0.0f));
  s.source = b.emissive() ? "emissive box over a white floor" : "red box on a white floor";
  return s;
}

// Floor points beside the box's sunlit +x face: 4 distances × 4 positions across its width; for
// an emissive box, a 4 × 4 grid under it, 3/4 of its width.
std::vector<gs::ProbeQuery> receivers(const BoxSetup& b) {
  std::vector<gs::ProbeQuery> q;
  const float step = b.half / 2.0f;
  for (int z = 0; z < 4; ++z)
    for (int x = 0; x < 4; ++x) {
      gs::ProbeQuery pq{};
      const float across = float(b.centre().z) - 0.75f * b.half + step * float(z);
      pq.position = glm::vec4(float(b.centre().x) + b.half + step * (0.25f + float(x)), kFloorTop,
                              across, 0.0f);
      if (b.emissive())
        pq.position = glm::vec4(float(b.centre().x) - 0.75f * b.half + step * float(x), kFloorTop,
                                across, 0.0f);
      pq.normal = glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);
      pq.view = glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);
      q.push_back(pq);
    }
  return q;
}

struct Verdict {
  float meanRelativeError = 0.0f;  // over receivers, of the luminance
  float redOverGreen = 0.0f;       // of the receivers' mean irradiance
  glm::vec3 mean{0.0f};
};

float luminance(glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

Verdict judge(const std::vector<glm::vec3>& e) {
  Verdict v;
  for (const glm::vec3& x : e) v.mean += x / float(e.size());
  v.redOverGreen = v.mean.x / std::max(v.mean.y, 1e-6f);
  return v;
}

enum class BoxAs { CardsOn, CardsOff, Static };

// GI frames before a still box is measured: probes are vigilant (hysteresis 0.3) for their first
// 32 frames; 24 give the same figures as 32 and 48 (to 0.002).
constexpr int kFrames = 24;

// Called after each frame f (0-based) with the system, for measurements along the way.
using AfterFrame = std::function<void(int, GiSystem&)>;

// `frames` frames of the GI with the box as a moving object (cards on or off) or baked into the
// static SDF. With slideFrames > 0 the object arrives sliding along +x, 1 m a frame, and stands
// at its final pose from frame slideFrames on.
std::vector<glm::vec3> runGi(gpu::Context& ctx, const BoxSetup& b, BoxAs as, int frames,
                             int slideFrames = 0, const AfterFrame& after = {}) {
  const glm::vec3 lo = glm::vec3(b.centre()) - b.halfExtents();
  const glm::vec3 hi = glm::vec3(b.centre()) + b.halfExtents();
  const bool staticBox = as == BoxAs::Static;
  // The static control bakes the box into the SDF: the light cache lights it as any wall.
  test::AnalyticStack stack(
      1,
      [&](glm::vec3 p, float) {
        return staticBox ? std::min(test::sdFloor(p), test::sdBox(p, lo, hi)) : test::sdFloor(p);
      },
      [&](glm::vec3 c) {
        const bool onBox = staticBox && c.y > kFloorTop + 0.5f &&
                           glm::all(glm::greaterThan(c, lo - 2.0f)) &&
                           glm::all(glm::lessThan(c, hi + 2.0f));
        return test::uniformMaterial(packAlbedo(onBox ? b.albedo : glm::vec4(0.8f)), 0u);
      });
  ObjectLibrary library(ObjectSdfSettings{16, 32, 0.0, 2});
  const std::uint32_t box = library.addBox(b.halfExtents(), b.albedo, b.emission);
  InstanceSet instances;
  auto poseAt = [&](int f) {
    ObjectTransform pose;
    pose.translation = b.centre() - glm::dvec3(double(std::max(slideFrames - f, 0)), 0.0, 0.0);
    return pose;
  };
  const InstanceId id = instances.add(box, poseAt(0));
  GiSettings settings;
  settings.objects.cards = as == BoxAs::CardsOn;
  GiSystem gi(ctx, settings, 1);
  if (!staticBox) gi.setObjects(&library, &instances);
  const SceneLights lights = lightsFor(b);
  probe::ProbeFrameInputs in;
  in.cameraWorld = b.centre() + glm::dvec3(2.0 * b.half, 0.0, 0.0);
  in.viewDirection = glm::normalize(glm::vec3(-1.0f, -0.3f, 0.0f));
  for (int f = 0; f < frames; ++f) {
    if (f > 0 && f <= slideFrames) instances.move(id, poseAt(f));
    gi.update(stack.image, lights, in, std::uint64_t(f));
    if (after) after(f, gi);
  }
  return gi.irradiance(receivers(b));
}

// The path tracer's irradiance at the receivers (everything but the sun's direct term).
struct Reference {
  std::vector<glm::vec3> means;
  Verdict verdict;
};

Reference reference(const BoxSetup& b) {
  const TriangleScene scene = referenceScene(b);  // the tracer keeps a reference to it
  const PathTracer tracer(scene, lightsFor(b));
  std::vector<glm::vec3> positions, normals;
  for (const gs::ProbeQuery& q : receivers(b)) {
    positions.push_back(glm::vec3(q.position) + glm::vec3(0.0f, 1e-3f, 0.0f));
    normals.push_back(glm::vec3(q.normal));
  }
  Reference r;
  for (const IrradianceEstimate& e :
       tracer.irradiance(positions, normals, 2048, IrradianceKind::NoDirectLights))
    r.means.push_back(e.mean);
  r.verdict = judge(r.means);
  return r;
}

Verdict compare(const Reference& ref, const std::vector<glm::vec3>& gi) {
  Verdict v = judge(gi);
  double err = 0.0;
  for (std::size_t i = 0; i < gi.size(); ++i)
    err += std::abs(luminance(gi[i]) - luminance(ref.means[i])) / luminance(ref.means[i]);
  v.meanRelativeError = float(err / double(gi.size()));
  return v;
}

// Prints the verdict, with the red irradiance column by column (receivers are x-major within
// each z row: distance from the sunlit face, or position across under an emissive box).
Verdict report(const char* name, const BoxSetup& b, const Reference& ref,
               const std::vector<glm::vec3>& gi) {
  const Verdict v = compare(ref, gi);
  for (int x = 0; x < 4; ++x) {
    double g = 0.0, r = 0.0;
    for (int z = 0; z < 4; ++z) {
      g += gi[std::size_t(z * 4 + x)].x;
      r += ref.means[std::size_t(z * 4 + x)].x;
    }
    if (b.emissive())
      std::printf("  %s at x = %+.1f m from the box's centre: red %.4f vs %.4f (%.2f of it)\n",
                  name, b.half / 2.0f * (float(x) - 1.5f), g / 4.0, r / 4.0, g / r);
    else
      std::printf("  %s at %.1f m from the face: red %.4f vs %.4f (%.2f of it)\n", name,
                  b.half / 2.0f * (0.25f + float(x)), g / 4.0, r / 4.0, g / r);
  }
  const Verdict& e = ref.verdict;
  std::printf(
      "[figures] %s: mean E (%.4f, %.4f, %.4f) vs reference (%.4f, %.4f, %.4f); mean "
      "relative error %.3f; R/G %.3f vs %.3f (%.3f of it)\n",
      name, v.mean.x, v.mean.y, v.mean.z, e.mean.x, e.mean.y, e.mean.z, v.meanRelativeError,
      v.redOverGreen, e.redOverGreen, v.redOverGreen / e.redOverGreen);
  return v;
}

struct BounceResult {
  Verdict on, off, staticBox, expected;
  // Mean |E_on - E_static| / E_static (luminance) over the receivers farther than a quarter
  // probe spacing from the face: what the cards change against the same box lit as a wall.
  float onVsStatic = 0.0f;
};

BounceResult bounce(gpu::Context& ctx, const BoxSetup& b, bool staticControl) {
  const Reference ref = reference(b);
  std::printf("[figures] %.0f m box, probes every 8 m:\n", 2.0f * b.half);
  BounceResult r;
  r.expected = ref.verdict;
  const std::vector<glm::vec3> on = runGi(ctx, b, BoxAs::CardsOn, kFrames);
  r.on = report("cards on", b, ref, on);
  r.off = report("cards off", b, ref, runGi(ctx, b, BoxAs::CardsOff, kFrames));
  if (!staticControl) return r;
  const std::vector<glm::vec3> still = runGi(ctx, b, BoxAs::Static, kFrames);
  r.staticBox = report("static box", b, ref, still);
  double d = 0.0;
  for (std::size_t i = 0; i < on.size(); ++i)
    d += std::abs(luminance(on[i]) - luminance(still[i])) / luminance(still[i]);
  r.onVsStatic = float(d / double(on.size()));
  std::printf("[figures] cards on vs the same box static: mean relative difference %.3f\n",
              r.onVsStatic);
  return r;
}

// A box four probe spacings wide: the probes resolve the bounce's fall-off with distance.
// Measured on lavapipe (24 frames): against the path tracer, cards on 0.087 mean relative error
// (R/G 0.93 of the reference's), off 0.732 (R/G 0.80). Cards give what the same box baked into
// the static SDF gets from the light cache (0.80 / 0.98 / 0.86 of the reference's red at 2 / 10 /
// 18 m from the face, both ways): the rest is the probe field's resolution (probes every 8 m).
// With 6x6 irradiance maps the figures were 0.082 and R/G 0.88: an up-facing query then blended
// texels 11 degrees off the normal, whose lobes see the sunlit floor itself, a grey 0.013 that
// padded the missing bounce; 8x8 maps (8 degrees) halve that leak.
TEST_F(ObjectCardBounce, RedBoxBouncesItsSunlightOntoTheFloor) {
  const BounceResult r = bounce(ctx(), BoxSetup{16.0f}, false);
  EXPECT_GT(r.expected.redOverGreen, 2.0f);  // the bounce is red: the test can tell
  EXPECT_GT(r.off.meanRelativeError, 0.5f);  // without cards the bounce is missing
  EXPECT_LE(r.on.meanRelativeError, 0.10f);
  EXPECT_NEAR(r.on.redOverGreen / r.expected.redOverGreen, 1.0f, 0.10f);
}

// The same box slides 16 m into place, 1 m a frame, and stops: the frames after it stops until
// the floor beside it is within kSettled of the reference (mean relative error) and stays there.
// Measured on lavapipe: 0.113 and 0.103 on the first two frames after it stops, 0.087-0.098 from
// the third on, R/G 0.96 of the reference's. (With the static clearance at 0.2 spacing the box
// that stood there all along read 0.098 and the sliding one 0.098-0.107 from the second frame.)
TEST_F(ObjectCardBounce, ASlidingBoxSettlesWithinTenFramesOfStopping) {
  const BoxSetup b{16.0f};
  const Reference ref = reference(b);
  constexpr int kSlide = 16, kAfter = 10;
  constexpr float kSettled = 0.10f;
  const std::vector<gs::ProbeQuery> queries = receivers(b);
  int settledAt = -1;
  std::vector<float> errors;
  const std::vector<glm::vec3> last =
      runGi(ctx(), b, BoxAs::CardsOn, kSlide + kAfter, kSlide, [&](int f, GiSystem& gi) {
        if (f < kSlide) return;
        const Verdict v = compare(ref, gi.irradiance(queries));
        errors.push_back(v.meanRelativeError);
        if (v.meanRelativeError > kSettled)
          settledAt = -1;
        else if (settledAt < 0)
          settledAt = f - kSlide + 1;
      });
  std::printf("[figures] sliding box, mean relative error frame by frame after it stops:");
  for (float e : errors) std::printf(" %.3f", e);
  std::printf("\n[figures] within %.0f%% from frame %d after it stops on (goal <= 10)\n",
              100.0f * kSettled, settledAt);
  const Verdict v = report("sliding box, 10 frames after it stops", b, ref, last);
  EXPECT_GE(settledAt, 1);
  EXPECT_LE(settledAt, kAfter);
  EXPECT_LE(v.meanRelativeError, kSettled);
  EXPECT_NEAR(v.redOverGreen / ref.verdict.redOverGreen, 1.0f, 0.10f);
}

// An emissive panel (a glowing underside: 24 × 4 × 24 m, warm light, grey albedo) hovering 4 m
// above the floor, no other light: the floor under it against the path tracer. Its light reaches
// the probes only through object hits (the card light's emission), and the probes around it live
// although no static surface is near some of them. Measured on lavapipe (24 frames): mean
// relative error 0.088, R/G exact. What is left is the probe field's, not the object's: the
// floor's probes are relocated 0.15 spacing (1.2 m) up, out of the floor, and so read an emitter
// 2.8 m away instead of 4 m (at 0.2 spacing: 1.6 m, 0.138). A compact emitter fares worse: an 8 m
// cube 8 m up reads 1.5x at 0.2 spacing, as the receiver's bias puts 0.225 of the weight on the
// probe layer under its bottom face.
TEST_F(ObjectCardBounce, AnEmissiveObjectLightsTheFloorUnderIt) {
  BoxSetup b;
  b.half = 12.0f;
  b.halfHeight = 2.0f;
  b.lift = 4.0f;
  b.albedo = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  b.emission = glm::vec3(4.0f, 2.0f, 1.0f);
  const Reference ref = reference(b);
  std::printf("[figures] 24 m emissive panel 4 m over the floor, probes every 8 m:\n");
  const Verdict v = report("emissive panel", b, ref, runGi(ctx(), b, BoxAs::CardsOn, kFrames));
  EXPECT_GT(ref.verdict.mean.x, 0.1f);  // the floor is lit: the test can tell
  EXPECT_LE(v.meanRelativeError, 0.10f);
  EXPECT_NEAR(v.redOverGreen / ref.verdict.redOverGreen, 1.0f, 0.10f);
}

// Figures only (the suite's time: run with --gtest_also_run_disabled_tests): the 32 m box with
// the static control, then a box one probe spacing wide. There cards triple the red bounce too,
// but probes 8 m apart cannot follow a bounce that falls from 0.85 to 0.19 within the box's
// width: the probe field's resolution, not the cards, limits it.
TEST_F(ObjectCardBounce, DISABLED_FiguresWithTheStaticControl) {
  const BounceResult r = bounce(ctx(), BoxSetup{16.0f}, true);
  EXPECT_LE(r.onVsStatic, 0.08f);  // cards give the object what the light cache gives a wall
  bounce(ctx(), BoxSetup{4.0f}, true);
}

}  // namespace
}  // namespace sdfstream
