#include "raster/mesh_view_raster.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "gpu/command_batch.h"
#include "gpu/context.h"
#include "world/color_pack.h"

namespace sdfstream {
namespace {

gpu::Buffer uploadPositions(gpu::Context& ctx, const TriangleScene& scene) {
  std::vector<glm::vec4> positions(scene.positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i)
    positions[i] = glm::vec4(scene.positions[i], 1);
  gpu::Buffer b(ctx, positions.size() * sizeof(glm::vec4), gpu::BufferKind::DeviceLocal);
  if (!positions.empty()) b.upload(positions.data(), positions.size() * sizeof(glm::vec4));
  return b;
}

gpu::Buffer uploadIndices(gpu::Context& ctx, const TriangleScene& scene) {
  for (const glm::uvec3& t : scene.triangles)
    if (t.x >= scene.positions.size() || t.y >= scene.positions.size() ||
        t.z >= scene.positions.size())
      throw InputError(InputErrorKind::Malformed, scene.source,
                       "a triangle's vertex index is out of range (" +
                           std::to_string(scene.positions.size()) + " vertices)");
  const std::size_t bytes = scene.triangles.size() * sizeof(glm::uvec3);
  gpu::Buffer b(ctx, bytes, gpu::BufferKind::DeviceLocal);
  if (bytes) b.upload(scene.triangles.data(), bytes);
  return b;
}

}  // namespace

MeshViewRaster::MeshViewRaster(gpu::Context& ctx, const TriangleScene& scene)
    : ctx_(&ctx),
      scene_(&scene),
      pyramid_(buildTexturePyramid(scene)),
      raster_(ctx,
              VisibilityStages{gpu::ShaderId::view_visibility_vs, gpu::ShaderId::view_visibility_fs,
                               sizeof(gpu_shared::ViewRasterPush), true, "raster primary"}),
      positions_(uploadPositions(ctx, scene)),
      indices_(uploadIndices(ctx, scene)) {}

VisibilityImage MeshViewRaster::render(const gpu_shared::ViewRasterPush& view, int width,
                                       int height) {
  const std::uint32_t w = std::uint32_t(width), h = std::uint32_t(height);
  const std::size_t bytes = VisibilityRaster::outputBytes(w, h);
  if (!readback_ || readback_.size() < bytes)
    readback_ = gpu::Buffer(*ctx_, bytes, gpu::BufferKind::Readback);
  const VisibilityView whole{0, 0, w, h, &view};
  gpu::CommandBatch batch = ctx_->beginBatch(1);
  batch.record("raster primary", [&](VkCommandBuffer cb) {
    raster_.record(cb, positions_, indices_, std::uint32_t(scene_->triangles.size()), w, h,
                   {&whole, 1}, readback_);
  });
  batch.submitAndWait();
  lastMilliseconds_ = batch.timings().front().milliseconds;

  VisibilityImage out;
  out.width = width;
  out.height = height;
  const std::size_t pixels = std::size_t(w) * h;
  out.triangle.resize(pixels);
  out.bary.resize(pixels);
  const auto* ids = static_cast<const std::uint32_t*>(readback_.mapped());
  std::memcpy(out.triangle.data(), ids, pixels * sizeof(std::uint32_t));
  std::memcpy(out.bary.data(), ids + pixels, pixels * sizeof(glm::vec2));
  return out;
}

std::vector<gpu_shared::PrimarySurface> resolvePrimarySurfaces(
    const TriangleScene& scene, const TexturePyramid& pyramid, const VisibilityImage& image,
    const glm::dvec3& eye, double pixelAngle, const glm::dvec3& stackOrigin, double voxelSize) {
  std::vector<gpu_shared::PrimarySurface> out(image.triangle.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size(), 1024), [&](auto range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      gpu_shared::PrimarySurface& s = out[i];
      s = {};
      const std::uint32_t id = image.triangle[i];
      if (id == 0 || id > scene.triangles.size()) continue;
      const std::uint32_t tri = id - 1;
      const glm::uvec3 t = scene.triangles[tri];
      const glm::dvec3 v0(scene.positions[t.x]), v1(scene.positions[t.y]), v2(scene.positions[t.z]);
      const glm::dvec2 b(image.bary[i]);
      const glm::dvec3 p = v0 * (1.0 - b.x - b.y) + v1 * b.x + v2 * b.y;
      const glm::dvec3 toEye = eye - p;
      glm::dvec3 n = glm::cross(v1 - v0, v2 - v0);
      const double area = glm::length(n);
      // Both sides of a triangle are surfaces (the SDF's rule for open sheets): the side facing
      // the camera is the one lit. A degenerate triangle faces the camera.
      n = area > 0.0 ? n / area : glm::normalize(toEye);
      const double distance = glm::length(toEye);
      if (glm::dot(n, toEye) < 0.0) n = -n;
      // The pixel's footprint: distance × angle across the view, stretched by 1/cos along the
      // slope; the geometric mean of the two axes, 1/sqrt(cos), keeps grazing floors from
      // blurring to their mean colour (a trilinear sampler without anisotropy).
      const double cosine = std::max(glm::dot(n, toEye) / std::max(distance, 1e-12), 0.05);
      const float footprint = float(distance * pixelAngle / std::sqrt(cosine));
      s.position = glm::vec4(glm::vec3((p - stackOrigin) / voxelSize), 1.0f);
      s.normalT = glm::vec4(glm::vec3(n), float(distance / voxelSize));
      s.albedo = packAlbedo(sampleAlbedo(scene, pyramid, tri, image.bary[i], footprint));
      s.emission = packRgb9e5(sampleEmission(scene, pyramid, tri, image.bary[i], footprint));
    }
  });
  return out;
}

}  // namespace sdfstream
