// The camera's primary view of a triangle scene through the visibility raster
// (visibility_raster.h): the scene's triangles are uploaded once, each view rasterizes which
// triangle every pixel sees, and resolvePrimarySurfaces turns that into the surfaces the shading
// pass lights (shaders/shared/shade_layout.h, PrimarySurface; demo/gi_shading.h). The mesh gives
// the picture its geometric and texture detail; the lighting, direct and indirect, still comes
// from the SDF cascades and the probes, as an engine that rasterizes its meshes and samples the
// probe field would show it.
//
// Thread safety: as for the Context. The scene must outlive the raster.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/buffer.h"
#include "gpu/command_batch.h"
#include "gpu/compute_pipeline.h"
#include "raster/visibility_raster.h"
#include "shaders/shared/shade_layout.h"
#include "shaders/shared/view_raster_layout.h"
#include "world/triangle_scene.h"

namespace sdfstream {

// A rasterized view: per pixel, row-major from the top-left, the triangle seen (index + 1, 0 =
// nothing) and its barycentrics (b1, b2) of vertices 1 and 2, as sampleAlbedo takes them.
struct VisibilityImage {
  int width = 0, height = 0;
  std::vector<std::uint32_t> triangle;
  std::vector<glm::vec2> bary;
};

class MeshViewRaster {
 public:
  // Uploads the scene's positions and indices to the device. Throws std::runtime_error as
  // VisibilityRaster does, or InputError(Malformed) naming scene.source when an index is out of
  // range.
  MeshViewRaster(gpu::Context& ctx, const TriangleScene& scene);

  // Rasterizes one view (clip from world: shared/view_raster_layout.h) at width x height;
  // blocking (the resolve reads the result on the host).
  VisibilityImage render(const gpu_shared::ViewRasterPush& view, int width, int height);

  // The device-resident path: records the view's visibility buffer into `visibility`
  // (VisibilityRaster::outputBytes), then its surfaces into `surfaces` (one PrimarySurface a
  // pixel, as resolvePrimarySurfaces with the same arguments, in float: raster_resolve.comp).
  // Nothing is read back; the buffers must outlive the batch.
  void record(gpu::CommandBatch& batch, const gpu_shared::ViewRasterPush& view, int width,
              int height, const gpu::Buffer& visibility);
  void recordResolve(gpu::CommandBatch& batch, int width, int height, const glm::dvec3& eye,
                     double pixelAngle, const glm::dvec3& stackOrigin, double voxelSize,
                     const gpu::Buffer& visibility, const gpu::Buffer& surfaces);
  // GPU time of the last render's draw and copies (0 without timestamps).
  double lastMilliseconds() const { return lastMilliseconds_; }
  const TriangleScene& scene() const { return *scene_; }
  // The scene's textures' mip chains (built once, on construction), for resolvePrimarySurfaces.
  const TexturePyramid& pyramid() const { return pyramid_; }

 private:
  gpu::Context* ctx_;
  const TriangleScene* scene_;
  TexturePyramid pyramid_;
  VisibilityRaster raster_;
  gpu::Buffer positions_, indices_, readback_;
  // The materials on the device for raster_resolve.comp (uploaded on construction).
  gpu::ComputePipeline resolve_;
  gpu::Buffer uvs_, triangleMaterial_, materials_, textures_, levels_, texels_;
  std::uint32_t uvSets_ = 0;  // bit 0: UV set 0 present, bit 1: set 1
  double lastMilliseconds_ = 0.0;
};

// The primary surface of every pixel of `image`: the point on its triangle (interpolated in
// double precision), the triangle's geometric normal turned towards `eye`, and the material's
// base colour and emission at the point (sampleAlbedo / sampleEmission, the path tracer's own
// lookups), filtered over the pixel's footprint on the surface (`pixelAngle` radians a pixel,
// widened as the surface turns away from the eye) with the scene's mip chains. Positions and
// distances are converted to the stack frame: (world - stackOrigin) / voxelSize. Pixels that
// see nothing get position.w = 0.
std::vector<gpu_shared::PrimarySurface> resolvePrimarySurfaces(
    const TriangleScene& scene, const TexturePyramid& pyramid, const VisibilityImage& image,
    const glm::dvec3& eye, double pixelAngle, const glm::dvec3& stackOrigin, double voxelSize);

}  // namespace sdfstream
