// The raster primary (GiRenderer::setPrimaryMesh): the scene's triangles rasterized into a
// visibility buffer (raster/mesh_view_raster.h) become the primary surfaces, lit by the same
// direct light and probes as the SDF's traced hits. On the demo_gi scene (floor, red wall,
// pillar; demo_gi_scene.h):
//  - the visibility buffer sees, at each pixel centre, the triangle an exact ray cast (Embree)
//    finds, except within a pixel of an edge;
//  - given the SDF's own traced hits as surfaces, the given-surface shading reproduces the
//    traced shading, and the GPU pass matches its CPU reference (same GLSL);
//  - the rasterized frame shows the same light as the traced one: mean direct and indirect
//    radiance of the pixels both see agree, while the rasterized surfaces lie on the triangles
//    (the SDF's hits lie up to a voxel off them).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "demo/frame_image.h"
#include "demo/gi_shading.h"
#include "gpu/command_batch.h"
#include "shaders/shared/color_codec.h"
#include "raster/mesh_view_raster.h"
#include "reference/embree_scene.h"
#include "tests/demo/demo_gi_scene.h"
#include "tests/support/gpu_test.h"
#include "tests/support/test_data.h"
#include "world/obj_import.h"

namespace sdfstream {
namespace {

class RasterPrimaryTest : public test::GpuTest {};

struct DemoScene {
  TriangleScene triangles = test::demoGiTriangles();
  World world = meshToWorld(triangles, 0.0, ImportLimits{});
  CascadeImage cascade = buildCascade(world, cascadeOriginForWorld(world));
  CascadeStackImage image = stackImageOf(cascade);
};

TEST_F(RasterPrimaryTest, VisibilityBufferSeesWhatAnExactRayCastSees) {
  const DemoScene s;
  const Camera camera = test::demoGiCamera();
  constexpr int kW = 160, kH = 120;
  MeshViewRaster raster(ctx(), s.triangles);
  const VisibilityImage v = raster.render(viewRasterPush(camera, kW, kH), kW, kH);
  ASSERT_EQ(v.triangle.size(), std::size_t(kW) * kH);

  const EmbreeScene embree(s.triangles);
  // The pixel rays in world space: primaryRaysFrom with the camera at the origin of the frame.
  const auto rays = primaryRaysFrom(camera, kW, kH, glm::vec3(0.0f));
  std::size_t covered = 0, same = 0, sameSurface = 0, missedBoth = 0;
  double worstPositionError = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const glm::vec3 o = glm::vec3(camera.position), d(rays[i].dirTMax);
    const auto hit = embree.intersect(o, d, 0.0f, 1e30f);
    if (!hit) {
      missedBoth += v.triangle[i] == 0 ? 1 : 0;
      continue;
    }
    ++covered;
    if (v.triangle[i] == hit->triangle + 1) {
      ++same;
      // The interpolated point against the exact one.
      const glm::uvec3 t = s.triangles.triangles[hit->triangle];
      const glm::vec2 b = v.bary[i];
      const glm::vec3 p = s.triangles.positions[t.x] * (1.0f - b.x - b.y) +
                          s.triangles.positions[t.y] * b.x + s.triangles.positions[t.z] * b.y;
      worstPositionError = std::max(worstPositionError, double(glm::length(p - (o + d * hit->t))));
    } else if (v.triangle[i] != 0) {
      // Another triangle of the same plane (a quad's other half, a coplanar face) is the same
      // surface; only a different depth is a disagreement.
      const glm::uvec3 t = s.triangles.triangles[v.triangle[i] - 1];
      const glm::vec3 a = s.triangles.positions[t.x], b = s.triangles.positions[t.y],
                      c = s.triangles.positions[t.z];
      const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
      const float along = glm::dot(n, a - o) / glm::dot(n, d);
      if (std::abs(along - hit->t) < 1e-3f) ++sameSurface;
    }
  }
  std::printf(
      "%zu of %zu pixels covered: %zu same triangle, %zu same plane, %zu both empty; "
      "worst position error %.2e m\n",
      covered, rays.size(), same, sameSurface, missedBoth, worstPositionError);
  ASSERT_GT(covered, rays.size() / 2);
  EXPECT_EQ(missedBoth, rays.size() - covered - 0) << "a pixel the ray cast misses is empty";
  // Pixel centres within a hair of an edge may go either way: allow one in a hundred.
  EXPECT_GE(same + sameSurface, covered - covered / 100);
  EXPECT_LT(worstPositionError, 1e-3);
}

TEST_F(RasterPrimaryTest, GivenTracedHitsShadeAsTheTraceAndMatchTheCpuReference) {
  const DemoScene s;
  const SceneLights lights = test::demoGiLights();
  GiRendererOptions options;
  options.gi = false;
  GiRenderer renderer(ctx(), options, 1);
  renderer.update(s.image, lights, {}, 0);
  constexpr int kW = 64, kH = 48;
  const ShadedView traced = renderer.shade(test::demoGiCamera(), kW, kH, s.image, lights);

  // The traced hits as given surfaces: the same point, normal and material.
  std::vector<gpu_shared::PrimarySurface> given(traced.shaded.size());
  for (std::size_t i = 0; i < given.size(); ++i) {
    const gpu_shared::ShadedHit& h = traced.shaded[i];
    if (!(h.flags & gpu_shared::kHitFlagHit)) continue;
    const glm::vec3 p =
        glm::vec3(traced.rays[i].originTMin) + glm::vec3(traced.rays[i].dirTMax) * h.normalT.w;
    given[i].position = glm::vec4(p, 1.0f);
    given[i].normalT = h.normalT;
    given[i].albedo = h.albedo;
    given[i].emission = h.emission;
  }
  PrimaryShadePass pass(ctx());
  GpuStackScene scene(ctx());
  scene.uploadAll(s.image);
  const auto gpuLights = toGpu(lights.lights, s.image);
  const auto sky = toGpu(lights.sky);
  const auto gpu = pass.run(scene, nullptr, traced.rays, gpuLights, sky, options.shading,
                            s.image.voxelSize0, nullptr, given);
  const auto cpu =
      shadePrimaryCpu(s.image, traced.rays, gpuLights, sky, options.shading, {}, given);
  ASSERT_EQ(gpu.size(), given.size());
  std::size_t hits = 0, differFromTrace = 0, differFromCpu = 0;
  for (std::size_t i = 0; i < gpu.size(); ++i) {
    const bool hit = traced.shaded[i].flags & gpu_shared::kHitFlagHit;
    EXPECT_EQ(bool(gpu[i].flags & gpu_shared::kHitFlagHit), hit) << "pixel " << i;
    const glm::vec3 g(gpu[i].direct), c(cpu[i].direct), t(traced.shaded[i].direct);
    if (glm::length(g - c) > 1e-4f + 1e-3f * glm::length(c)) ++differFromCpu;
    if (!hit) continue;
    ++hits;
    if (glm::length(g - t) > 1e-3f + 1e-2f * glm::length(t)) ++differFromTrace;
  }
  std::printf("%zu hits: %zu differ from the traced shading, %zu from the CPU reference\n", hits,
              differFromTrace, differFromCpu);
  ASSERT_GT(hits, gpu.size() / 2);
  EXPECT_LE(differFromCpu, gpu.size() / 1000);
  // The shadow walk starts from the same point in the same cascade: only a penumbra pixel or
  // two may round the other way.
  EXPECT_LE(differFromTrace, hits / 100);
}

TEST_F(RasterPrimaryTest, RasterizedFrameShowsTheSameLightAsTheTracedOne) {
  const DemoScene s;
  const SceneLights lights = test::demoGiLights();
  const Camera camera = test::demoGiCamera();
  constexpr int kW = 128, kH = 96, kGiFrames = 12;
  const auto renderer = test::demoGiRenderer(ctx(), s.image, lights, camera, kGiFrames);
  GiRenderer& gi = *renderer;
  const ShadedView tracedView = gi.shade(camera, kW, kH, s.image, lights);
  const HdrFrame traced = gi.finish(tracedView);
  gi.setPrimaryMesh(&s.triangles);
  ASSERT_TRUE(gi.rastersPrimary());
  const ShadedView rasterView = gi.shade(camera, kW, kH, s.image, lights);
  const HdrFrame raster = gi.finish(rasterView);
  EXPECT_GT(gi.lastTimes().rasterMilliseconds, 0.0);

  const auto out = test::scratchDir("raster-primary");
  writePng(out / "traced.png", toneMap(traced.final(), kW, kH, 0.0f));
  writePng(out / "raster.png", toneMap(raster.final(), kW, kH, 0.0f));
  glm::dvec3 directT(0.0), directR(0.0), indirectT(0.0), indirectR(0.0);
  std::size_t both = 0;
  for (std::size_t i = 0; i < raster.direct.size(); ++i) {
    const bool t = tracedView.shaded[i].flags & gpu_shared::kHitFlagHit;
    const bool r = rasterView.shaded[i].flags & gpu_shared::kHitFlagHit;
    if (!t || !r) continue;
    ++both;
    directT += glm::dvec3(traced.direct[i]);
    directR += glm::dvec3(raster.direct[i]);
    indirectT += glm::dvec3(traced.indirect[i]);
    indirectR += glm::dvec3(raster.indirect[i]);
  }
  const double dT = test::lum(directT), dR = test::lum(directR);
  const double iT = test::lum(indirectT), iR = test::lum(indirectR);
  std::printf(
      "images in %s; %zu of %zu hits both ways (traced %zu, raster %zu): direct %.4f vs "
      "%.4f, indirect %.4f vs %.4f (mean luminance, traced vs raster)\n",
      out.c_str(), both, raster.direct.size(), traced.hits, raster.hits, dT / double(both),
      dR / double(both), iT / double(both), iR / double(both));
  ASSERT_GT(both, raster.direct.size() / 2);
  EXPECT_NEAR(dR / dT, 1.0, 0.05);
  EXPECT_NEAR(iR / iT, 1.0, 0.10);
  // Pixels one sees and the other does not: silhouettes only.
  const std::size_t hitsDiffer = std::max(traced.hits, raster.hits) - both;
  EXPECT_LT(hitsDiffer, both / 20);
}

// The visibility buffer resolved on the device (raster_resolve.comp) against
// resolvePrimarySurfaces on the host, on the demo scene with a texture: a colour checker on the
// floor, its UVs a few tiles a metre, seen near and far so several mip levels are used.
TEST_F(RasterPrimaryTest, DeviceResolveMatchesTheHostResolve) {
  TriangleScene s = test::demoGiTriangles();
  Texture checker;
  checker.width = checker.height = 32;
  checker.rgba.resize(32 * 32 * 4);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      std::uint8_t* t = &checker.rgba[(y * 32 + x) * 4];
      t[0] = std::uint8_t((x * 37 + y * 11) % 256);
      t[1] = std::uint8_t((x + y) % 2 ? 230 : 40);
      t[2] = std::uint8_t((y * 53) % 256);
      t[3] = 255;
    }
  s.textures = {checker};
  s.uvs.resize(s.positions.size());
  for (std::size_t i = 0; i < s.positions.size(); ++i)
    s.uvs[i] = glm::vec2(s.positions[i].x, s.positions[i].z) * 0.75f;
  for (Material& m : s.materials) m.baseColorTexture = 0;
  s.materials[0].emissive = glm::vec3(0.5f, 0.25f, 0.0f);
  s.materials[0].emissiveTexture = 0;
  const Camera camera = test::demoGiCamera();
  constexpr int kW = 160, kH = 120;
  MeshViewRaster raster(ctx(), s);
  const glm::dvec3 origin(-3.0, -1.0, -3.0);
  const double voxel = 0.05, pixelAngle = 2.0 * std::tan(glm::radians(55.0) * 0.5) / kH;
  const auto push = viewRasterPush(camera, kW, kH);
  const std::size_t pixels = std::size_t(kW) * kH;
  gpu::Buffer visibility(ctx(), VisibilityRaster::outputBytes(kW, kH),
                         gpu::BufferKind::DeviceLocal);
  gpu::Buffer surfaces(ctx(), pixels * sizeof(gpu_shared::PrimarySurface),
                       gpu::BufferKind::DeviceLocal);
  gpu::CommandBatch batch = ctx().beginBatch();
  raster.record(batch, push, kW, kH, visibility);
  raster.recordResolve(batch, kW, kH, camera.position, pixelAngle, origin, voxel, visibility,
                       surfaces);
  batch.submitAndWait();
  std::vector<gpu_shared::PrimarySurface> gpu(pixels);
  surfaces.download(gpu.data(), pixels * sizeof(gpu_shared::PrimarySurface));
  const VisibilityImage image = raster.render(push, kW, kH);
  const auto cpu = resolvePrimarySurfaces(s, raster.pyramid(), image, camera.position, pixelAngle,
                                          origin, voxel);
  std::size_t hits = 0, geometry = 0, colour = 0, emission = 0;
  int worstChannel = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    ASSERT_EQ(gpu[i].position.w, cpu[i].position.w) << "pixel " << i;
    if (cpu[i].position.w == 0.0f) continue;
    ++hits;
    const float d = glm::length(glm::vec3(gpu[i].position) - glm::vec3(cpu[i].position));
    const float n = glm::dot(glm::vec3(gpu[i].normalT), glm::vec3(cpu[i].normalT));
    if (d > 1e-2f || n < 0.9999f || std::abs(gpu[i].normalT.w - cpu[i].normalT.w) > 1e-2f)
      ++geometry;
    int channel = 0;
    for (int c = 0; c < 4; ++c)
      channel = std::max(channel, std::abs(int((gpu[i].albedo >> (8 * c)) & 255u) -
                                           int((cpu[i].albedo >> (8 * c)) & 255u)));
    worstChannel = std::max(worstChannel, channel);
    colour += channel > 2 ? 1 : 0;
    const glm::vec3 eg = gpu_shared::unpackRgb9e5(gpu[i].emission),
                    ec = gpu_shared::unpackRgb9e5(cpu[i].emission);
    emission += glm::length(eg - ec) > 0.01f * (glm::length(ec) + 0.01f) ? 1 : 0;
  }
  std::printf(
      "%zu hits: %zu geometry, %zu colour (> 2 levels; worst %d), %zu emission "
      "differences\n",
      hits, geometry, colour, worstChannel, emission);
  ASSERT_GT(hits, pixels / 2);
  // The texture was read (filtered colours of the checker, not one factor).
  std::set<std::uint32_t> distinct;
  for (const auto& c : cpu) distinct.insert(c.albedo);
  EXPECT_GT(distinct.size(), 500u);
  EXPECT_EQ(geometry, 0u);
  // Float against double footprints may pick a slightly different mip blend at a few pixels.
  EXPECT_LE(colour, hits / 200);
  EXPECT_LE(emission, hits / 200);
}

// The Cornell box (real data) seen from above, where its ceiling is one open sheet: the
// rasterized ceiling lies on the sheet, inside the SDF's shell around it (its surface half a
// voxel above), so its shadow rays must start outside that shell to see the sun as the traced
// hit's do (shadeSurfaceShadowOrigin).
TEST_F(RasterPrimaryTest, CornellBoxFromAboveIsLitAlike) {
  SDFSTREAM_REQUIRE_SHARED_DATA("cornell-box/CornellBox-Original.obj");
  const TriangleScene triangles =
      loadObj(test::sharedData() / "cornell-box/CornellBox-Original.obj");
  const World world = meshToWorld(triangles, 0.02, ImportLimits{});
  const CascadeImage cascade = buildCascade(world, cascadeOriginForWorld(world));
  const CascadeStackImage image = stackImageOf(cascade);
  const SceneLights lights = defaultSceneLights(glm::vec3(-0.3f, -1.0f, -0.2f), 3.0f,
                                                glm::vec3(0.2f, 0.3f, 0.5f), glm::vec3(0.5f));
  Camera camera;
  camera.position = glm::dvec3(1.3, 4.1, -0.02);
  camera.target = glm::dvec3(0.0, 1.0, -0.02);
  constexpr int kW = 96, kH = 64;
  GiRendererOptions options;
  options.gi = false;
  GiRenderer renderer(ctx(), options, 1);
  renderer.update(image, lights, {}, 0);
  const HdrFrame traced = renderer.render(camera, kW, kH, image, lights);
  renderer.setPrimaryMesh(&triangles);
  const HdrFrame raster = renderer.render(camera, kW, kH, image, lights);
  double t = 0.0, r = 0.0;
  for (std::size_t i = 0; i < traced.direct.size(); ++i) {
    t += test::lum(glm::dvec3(traced.direct[i]));
    r += test::lum(glm::dvec3(raster.direct[i]));
  }
  std::printf("hits traced %zu raster %zu; mean direct luminance traced %.4f raster %.4f\n",
              traced.hits, raster.hits, t / traced.direct.size(), r / raster.direct.size());
  EXPECT_NEAR(r / t, 1.0, 0.05);
}

}  // namespace
}  // namespace sdfstream
