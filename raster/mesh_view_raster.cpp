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

template <typename T>
gpu::Buffer uploadVector(gpu::Context& ctx, const std::vector<T>& v) {
  gpu::Buffer b(ctx, std::max<std::size_t>(v.size() * sizeof(T), 4), gpu::BufferKind::DeviceLocal);
  if (!v.empty()) b.upload(v.data(), v.size() * sizeof(T));
  return b;
}

glm::vec4 uvColumns(const UvTransform& t) {
  return glm::vec4(t.column0.x, t.column0.y, t.column1.x, t.column1.y);
}

// Every level of every texture as RGBA8 words, level 0 first (the texture itself), then the
// pyramid's; a texture that is not a whole image gets no levels (white).
void packTextures(const TriangleScene& scene, const TexturePyramid& pyramid,
                  std::vector<gpu_shared::RasterTextureGpu>& textures,
                  std::vector<gpu_shared::RasterLevelGpu>& levels,
                  std::vector<std::uint32_t>& texels) {
  auto addLevel = [&](const Texture& t) {
    levels.push_back({glm::uvec4(std::uint32_t(texels.size()), std::uint32_t(t.width),
                                 std::uint32_t(t.height), 0u)});
    const std::size_t first = texels.size();
    texels.resize(first + t.rgba.size() / 4);
    std::memcpy(texels.data() + first, t.rgba.data(), t.rgba.size());
  };
  for (std::size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture& t = scene.textures[i];
    gpu_shared::RasterTextureGpu entry{glm::uvec4(std::uint32_t(levels.size()), 0u, 0u, 0u)};
    const bool whole = t.width > 0 && t.height > 0 &&
                       t.rgba.size() == std::size_t(t.width) * std::size_t(t.height) * 4;
    if (whole) {
      addLevel(t);
      if (i < pyramid.levels.size())
        for (const Texture& level : pyramid.levels[i]) addLevel(level);
      entry.levels.y = std::uint32_t(levels.size()) - entry.levels.x;
    }
    textures.push_back(entry);
  }
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
      indices_(uploadIndices(ctx, scene)),
      resolve_(ctx, gpu::ShaderId::raster_resolve,
               gpu::PipelineDesc{10, sizeof(gpu_shared::RasterResolvePush), glm::uvec3(64, 1, 1)}) {
  const std::size_t vertices = scene.positions.size();
  const bool set0 = scene.uvs.size() == vertices, set1 = scene.uvs1.size() == vertices;
  uvSets_ = (set0 ? 1u : 0u) | (set1 ? 2u : 0u);
  std::vector<glm::vec4> uvs(vertices, glm::vec4(0.0f));
  for (std::size_t i = 0; i < vertices; ++i)
    uvs[i] =
        glm::vec4(set0 ? scene.uvs[i] : glm::vec2(0.0f), set1 ? scene.uvs1[i] : glm::vec2(0.0f));
  uvs_ = uploadVector(ctx, uvs);
  std::vector<std::uint32_t> triangleMaterial(scene.triangles.size(), 0u);
  for (std::size_t t = 0; t < triangleMaterial.size() && t < scene.triangleMaterial.size(); ++t)
    triangleMaterial[t] =
        scene.triangleMaterial[t] < scene.materials.size() ? scene.triangleMaterial[t] : 0u;
  triangleMaterial_ = uploadVector(ctx, triangleMaterial);
  std::vector<gpu_shared::RasterMaterialGpu> materials;
  for (const Material& m : scene.materials) {
    gpu_shared::RasterMaterialGpu g{};
    g.baseColorFactor = m.baseColorFactor;
    g.emissive = glm::vec4(m.emissive, 0.0f);
    g.textures =
        glm::ivec4(m.baseColorTexture, m.baseColorTexCoord, m.emissiveTexture, m.emissiveTexCoord);
    g.baseUv = uvColumns(m.baseColorUv);
    g.emissiveUv = uvColumns(m.emissiveUv);
    g.uvOffsets = glm::vec4(m.baseColorUv.offset, m.emissiveUv.offset);
    materials.push_back(g);
  }
  if (materials.empty()) materials.push_back({glm::vec4(1.0f), glm::vec4(0.0f), glm::ivec4(-1)});
  materials_ = uploadVector(ctx, materials);
  std::vector<gpu_shared::RasterTextureGpu> textures;
  std::vector<gpu_shared::RasterLevelGpu> levels;
  std::vector<std::uint32_t> texels;
  packTextures(scene, pyramid_, textures, levels, texels);
  textures_ = uploadVector(ctx, textures);
  levels_ = uploadVector(ctx, levels);
  texels_ = uploadVector(ctx, texels);
}

void MeshViewRaster::record(gpu::CommandBatch& batch, const gpu_shared::ViewRasterPush& view,
                            int width, int height, const gpu::Buffer& visibility) {
  const VisibilityView whole{0, 0, std::uint32_t(width), std::uint32_t(height), &view};
  batch.record("raster primary", [&](VkCommandBuffer cb) {
    raster_.record(cb, positions_, indices_, std::uint32_t(scene_->triangles.size()),
                   std::uint32_t(width), std::uint32_t(height), {&whole, 1}, visibility);
  });
}

void MeshViewRaster::recordResolve(gpu::CommandBatch& batch, int width, int height,
                                   const glm::dvec3& eye, double pixelAngle,
                                   const glm::dvec3& stackOrigin, double voxelSize,
                                   const gpu::Buffer& visibility, const gpu::Buffer& surfaces) {
  gpu_shared::RasterResolvePush push{};
  push.eye = glm::vec4(glm::vec3(eye), float(pixelAngle));
  push.stackOrigin = glm::vec4(glm::vec3(stackOrigin), float(1.0 / voxelSize));
  push.size = glm::uvec4(std::uint32_t(width), std::uint32_t(height),
                         std::uint32_t(scene_->triangles.size()), uvSets_);
  batch.dispatch("raster_resolve", resolve_,
                 {&visibility, &positions_, &indices_, &uvs_, &triangleMaterial_, &materials_,
                  &textures_, &levels_, &texels_, &surfaces},
                 &push, sizeof push,
                 gpu::spreadOverRows(std::uint32_t(width) * std::uint32_t(height)));
}

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
