// Final shading of the demo frames with the GI core: each primary ray is traced through the cascade
// stack and shaded on the GPU (shade_primary.comp: emission + albedo/π · E_direct, or the sky on a
// miss), then the probe field adds albedo/π · E_indirect, E_indirect = GiSystem::irradiance(x, n,
// view) batched over every hit pixel. The result is linear radiance per pixel, kept as its direct
// and indirect parts so a reader can see the indirect light alone; demo/frame_image.h tone-maps it.
//
// Moving objects (GiRenderer::setObjects): the GPU pass also searches the objects in
// front of each static hit and shades the nearer object hit (its direct light, then its indirect
// light from the same probe query at the object's surface), and objects block every shadow ray
// (hard shadows), so they darken the direct light of what lies under them; the probes see them
// too, which darkens the indirect light there (their indirect shadow).
//
// The primary surfaces can instead be rasterized from the source triangles
// (GiRenderer::setPrimaryMesh, raster/mesh_view_raster.h) and lit the same way. shade + finish
// return the frame to the host (render, demo, fly, tests); renderPicture keeps the whole frame on
// the GPU and returns only the tone-mapped picture (the viewer).
//
// Used by `sdfstream render`, `demo` (one cascade built from the world, demo/view_renderer.h),
// `fly` and `view` (the streaming stack). Thread safety: as for the gpu::Context.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "demo/frame_image.h"
#include "gi/camera.h"
#include "gi/cpu_tracer.h"
#include "gi/gi_system.h"
#include "gi/gpu_stack_scene.h"
#include "gi/light_cache.h"
#include "gi/object_scene.h"
#include "gi/scene_lights.h"
#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/context.h"
#include "gpu/staged_buffer.h"
#include "raster/mesh_view_raster.h"
#include "shaders/shared/frame_layout.h"
#include "shaders/shared/shade_layout.h"
#include "streaming/cascade.h"
#include "streaming/cascade_stack.h"

namespace sdfstream {

struct ShadingSettings {
  TraceSettings trace;                                   // primary rays
  std::uint32_t direct = gpu_shared::kShadeDirectPixel;  // kShadeDirect* (shade_layout.h)
  std::uint32_t shadowSteps = 256;  // per shadow ray, all cascades (as the light cache)
  float shadowEpsilon = 0.02f;      // voxels
};

// The push constants both implementations of the shading pass run on. Asserts at most
// kMaxLights lights.
gpu_shared::ShadePushConstants shadePushConstants(const ShadingSettings& settings,
                                                  std::size_t rayCount, std::size_t lightCount,
                                                  std::uint32_t cascadeCount,
                                                  const gpu_shared::GpuSky& sky, double voxelSize0);

// CPU reference of shade_primary.comp (same GLSL compiled as C++, TBB over rays). Rays in
// cascade-0 voxels of `stack`; lights from toGpu(lights, stack). `lightRadiance` (one RGB9E5 per
// atlas material voxel, LightCacheCpu::radiance()) is read only with kShadeDirectCache and may be
// empty otherwise. `surfaces`: empty (trace every ray), or one given primary surface per ray
// (kShadePrimaryGiven, raster/mesh_view_raster.h). No moving objects: it equals the GPU pass run
// without any.
std::vector<gpu_shared::ShadedHit> shadePrimaryCpu(
    const CascadeStackImage& stack, std::span<const gpu_shared::TraceRay> rays,
    std::span<const gpu_shared::GpuLight> lights, const gpu_shared::GpuSky& sky,
    const ShadingSettings& settings, std::span<const std::uint32_t> lightRadiance,
    std::span<const gpu_shared::PrimarySurface> surfaces = {});

// The GPU shading pass. Owns its ray/result/light buffers (grown on demand).
class PrimaryShadePass {
 public:
  explicit PrimaryShadePass(gpu::Context& context);
  // Traces and shades `rays` against `scene` (synced to the stack the rays refer to); blocking.
  // lightRadiance: the light cache atlas (read with kShadeDirectCache), or nullptr. objects: the
  // moving objects, updated for the same stack this frame (ObjectScene::update), or nullptr;
  // an inactive scene counts as none. surfaces: empty (trace every ray) or one given primary
  // surface per ray (kShadePrimaryGiven).
  std::vector<gpu_shared::ShadedHit> run(const GpuStackScene& scene,
                                         const gpu::Buffer* lightRadiance,
                                         std::span<const gpu_shared::TraceRay> rays,
                                         std::span<const gpu_shared::GpuLight> lights,
                                         const gpu_shared::GpuSky& sky,
                                         const ShadingSettings& settings, double voxelSize0,
                                         const ObjectScene* objects = nullptr,
                                         std::span<const gpu_shared::PrimarySurface> surfaces = {});
  // Records the same pass into `batch` over `count` rays already on the device (`rays`, a view
  // made there), writing `shaded` on the device: nothing is read back. deviceSurfaces: the
  // given surfaces already on the device (one a ray; instead of `surfaces`). Until the batch has
  // completed, no other run() or record() of this pass (they share its staging buffers).
  void record(gpu::CommandBatch& batch, const GpuStackScene& scene,
              const gpu::Buffer* lightRadiance, const gpu::Buffer& rays, const gpu::Buffer& shaded,
              std::size_t count, std::span<const gpu_shared::GpuLight> lights,
              const gpu_shared::GpuSky& sky, const ShadingSettings& settings, double voxelSize0,
              const ObjectScene* objects = nullptr,
              std::span<const gpu_shared::PrimarySurface> surfaces = {},
              const gpu::Buffer* deviceSurfaces = nullptr);
  double lastMilliseconds() const { return milliseconds_; }

 private:
  gpu::Context& context_;
  gpu::ComputePipelinePair pipeline_;           // specialized on the atlas the scene traces
  gpu::StagedBuffer rays_, shaded_, surfaces_;  // device-local for the pass (staged_buffer.h)
  gpu::Buffer lights_, noRadiance_, noSurfaces_;
  NoObjectsBindings noObjects_;  // bound at 9-16 when there are no objects
  double milliseconds_ = 0.0;
};

// Linear radiance of one frame, split so each part can be written alone. Row-major from the
// top-left pixel. final = direct + indirect.
struct HdrFrame {
  int width = 0, height = 0;
  std::vector<glm::vec3> direct;    // hits: emission + albedo/π · E_direct; misses: the sky
  std::vector<glm::vec3> indirect;  // hits: albedo/π · E_indirect; misses: 0
  std::size_t hits = 0;
  std::size_t objectHits = 0;  // hits on a moving object (kShadeFlagObject), part of `hits`
  std::vector<glm::vec3> final() const;
};

// One primary ray per pixel (primaryRaysFrom) in cascade-0 voxels of `stack`, each starting where
// it enters the stack's outermost window: the stack traversal starts a ray only inside a window,
// and render/demo place the camera outside their one cascade. Rays that never enter it get
// tMin > tMax (a miss).
std::vector<gpu_shared::TraceRay> cameraRays(const Camera& camera, int width, int height,
                                             const CascadeStackImage& stack);

// Probe queries for the hit pixels of `shaded` (rays in cascade-0 voxels): position = the hit
// point, normal = the SDF normal (a moving object's: its own hit point and normal, which
// ShadedHit carries the same way), view = -ray direction. pixels[i] = the pixel of query i.
std::vector<gpu_shared::ProbeQuery> probeQueries(std::span<const gpu_shared::ShadedHit> shaded,
                                                 std::span<const gpu_shared::TraceRay> rays,
                                                 std::vector<std::uint32_t>& pixels);
// Builds the frame from shaded hits and the irradiance E_indirect of each query (empty: no GI).
HdrFrame composeFrame(std::span<const gpu_shared::ShadedHit> shaded, int width, int height,
                      std::span<const std::uint32_t> pixels,
                      std::span<const glm::vec3> indirectIrradiance);

// A one-cascade stack image over a single cascade window (render/demo): params offset 0, scale
// 1, toroidal from originBrick mod 16. Points into `cascade`'s atlas, which must outlive it.
CascadeStackImage stackImageOf(const CascadeImage& cascade);

// The default light rig of the demo views: sun + gradient sky (linear RGB, scene radiance scale).
SceneLights defaultSceneLights(glm::vec3 sunTravelDirection, float sunIrradiance,
                               glm::vec3 skyZenith, glm::vec3 skyHorizon);

// What GiRenderer::renderPicture shows (shaders/shared/frame_layout.h).
struct PictureSettings {
  std::uint32_t mode = gpu_shared::kFrameFinal;  // kFrame*: final, direct, indirect, debug views
  bool indirect = true;                          // kFrameFinal adds the indirect light (with GI on)
  float exposureStops = 0.0f;                    // as toneMap's
  float indirectStops = 2.0f;  // kFrameIndirect shows the indirect light this much brighter
};

struct GiRendererOptions {
  bool gi = true;  // false: direct light only (no probe field is allocated or updated)
  GiSettings settings;
  ShadingSettings shading;
};

struct GiFrameTimes {
  GiFrameStats gi;  // light cache, probe and object passes (GI off: light cache and objects only)
  std::vector<gpu::PassTiming> probePasses;  // the last update's probe passes, one by one
  double shadeMilliseconds = 0.0;            // shade_primary pass (trace + direct light)
  double rasterMilliseconds = 0.0;           // the raster primary's draw (0: SDF primary)
  double sampleMilliseconds = 0.0;           // probe_sample pass (irradiance queries)
};

// A view traced and shaded with direct light, waiting for its indirect light.
struct ShadedView {
  int width = 0, height = 0;
  std::vector<gpu_shared::TraceRay> rays;  // cascade-0 voxels of the stack it was traced in
  std::vector<gpu_shared::ShadedHit> shaded;
  std::vector<gpu_shared::ProbeQuery> queries;  // one per hit pixel (probeQueries)
  std::vector<std::uint32_t> pixels;            // the pixel of each query
};

// The GI core and the shading pass for a sequence of frames on one GPU. With GI off it keeps the
// stack's device copy itself (and the light cache only for kShadeDirectCache).
class GiRenderer {
 public:
  GiRenderer(gpu::Context& context, const GiRendererOptions& options, std::uint32_t cascades);
  ~GiRenderer();

  // Moving objects from the next update() on, or none (library nullptr, the default). Both must
  // outlive their use. Each update() then rebuilds the objects' GPU data for its stack, and
  // consumes the set's change record (instances->endFrame()): move the instances before it.
  // GI on: forwarded to GiSystem::setObjects (probes, light cache and primary shading see the
  // objects). GI off: the renderer keeps its own ObjectScene, so the primary pass still shows
  // the objects and their hard shadows in the per-pixel direct light, and with kShadeDirectCache
  // the light cache relights the pages they shadow, as GiSystem does. The CPU reference
  // (shadePrimaryCpu, --cpu) has no objects.
  void setObjects(const ObjectLibrary* library, InstanceSet* instances);
  bool hasObjects() const { return objectLibrary_ != nullptr; }

  // The primary surfaces from now on: rasterized from `scene`'s triangles (a visibility buffer,
  // raster/mesh_view_raster.h), whose detail the picture then shows, lit as the SDF's hits are
  // (direct light through the SDF shadows, indirect light from the probes); or, nullptr (the
  // default), traced through the SDF. The scene must be in the pack's world frame and outlive
  // its use. Throws as MeshViewRaster does.
  void setPrimaryMesh(const TriangleScene* scene);
  bool rastersPrimary() const { return raster_ != nullptr; }

  // One frame: sync the stack (whole image / streamed dirty slots), relight, update probes.
  GiFrameStats update(const CascadeStackImage& image, const SceneLights& lights,
                      const probe::ProbeFrameInputs& inputs, std::uint64_t frame);
  GiFrameStats update(const CascadeStack& stack, std::span<const std::uint32_t> dirtySlots,
                      const SceneLights& lights, const probe::ProbeFrameInputs& inputs,
                      std::uint64_t frame);

  // Traces and shades one view of the last updated stack (`image` is that stack), direct light
  // only; blocking. The shading does not depend on the probes, so a still image can be shaded
  // once and finished after the probes have converged.
  ShadedView shade(const Camera& camera, int width, int height, const CascadeStackImage& image,
                   const SceneLights& lights);
  // Adds the current probes' indirect light (nothing with GI off); blocking.
  HdrFrame finish(const ShadedView& view);
  HdrFrame render(const Camera& camera, int width, int height, const CascadeStackImage& image,
                  const SceneLights& lights) {
    return finish(shade(camera, width, height, image, lights));
  }
  // The view's picture composed on the GPU in one submission: the primary rays made there
  // (camera_rays.comp), traced and shaded as shade() does (or the raster primary's surfaces),
  // the probe field sampled per pixel as an engine's shader would (frame_compose.comp: the
  // installable sdfstream/probe_sample.glsl), tone-mapped there; only the picture (4 bytes a
  // pixel) is read back, not the hits (48) nor the queries. The same picture as
  // toneMap(finish(shade(...)).final(), exposure) and the viewer's debug views, to within a
  // level of rounding. lastTimes(): shade = rays + shading pass, sample = the compose pass.
  Image8 renderPicture(const Camera& camera, int width, int height, const CascadeStackImage& image,
                       const SceneLights& lights, const PictureSettings& settings);
  // Mean E_indirect over a fixed subset of receivers (a convergence probe; 0 with GI off).
  glm::vec3 meanIrradiance(std::span<const gpu_shared::ProbeQuery> queries);

  const GiFrameTimes& lastTimes() const { return times_; }
  bool giEnabled() const { return gi_ != nullptr; }
  std::size_t probeDeviceBytes() const;
  // The atlas slots the device could hold, at most `slots` (GpuStackScene::reserveAtlas): call
  // before the first update and keep the stack within them (CascadeStack::limitAtlasSlots).
  std::uint32_t reserveAtlasSlots(std::uint32_t slots);
  // After an update ran out of device memory (gpu::OutOfDeviceMemory): the atlas again, for at
  // most `slots` slots (GpuStackScene::shrinkAtlas); keep the stack within the result and pass
  // every resident slot as dirty to the next update.
  std::uint32_t shrinkAtlasSlots(std::uint32_t slots);

 private:
  const GpuStackScene& scene() const;
  const gpu::Buffer* lightRadiance() const;
  const ObjectScene* objectScene() const;
  GiFrameStats updateDirectOnly(const CascadeStackImage& image, const SceneLights& lights);

  gpu::Context& context_;
  GiRendererOptions options_;
  std::unique_ptr<GiSystem> gi_;                 // GI on
  std::unique_ptr<GpuStackScene> scene_;         // GI off
  std::unique_ptr<LightCache> light_;            // GI off with kShadeDirectCache
  std::unique_ptr<CascadeStackImage> previous_;  // GI off: for the light cache's dirty pages
  LightRelightQueue relight_;                    // GI off: which of them to relight now
  std::unique_ptr<ObjectScene> objects_;         // GI off with objects
  const ObjectLibrary* objectLibrary_ = nullptr;
  InstanceSet* instances_ = nullptr;
  std::uint64_t lightsVersion_ = ~std::uint64_t(0);
  PrimaryShadePass shade_;
  std::unique_ptr<MeshViewRaster> raster_;  // --primary raster
  struct PicturePasses;                     // renderPicture's pipelines and buffers
  std::unique_ptr<PicturePasses> picture_;
  GiFrameTimes times_;
};

}  // namespace sdfstream
