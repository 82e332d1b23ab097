#include "demo/gi_shading.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <glm/gtc/packing.hpp>

#include "gpu/command_batch.h"
#include "shaders/shared/color_codec.h"

namespace sdfstream {
namespace shade_detail {
using namespace glm;
using namespace gpu_shared;

// The GLSL functions become member functions; the macros read this object's pointers, which
// point into one CascadeStackImage, the light list and the light cache of one call. OBJ_FRAME
// stays undefined: the reference has no moving objects (shade_primary.glsl).
struct PrimaryShader {
  const std::uint32_t* pageTable = nullptr;
  const std::uint32_t* distanceAtlas = nullptr;
  const std::uint32_t* albedoAtlas = nullptr;
  const std::uint32_t* emissionAtlas = nullptr;
  const CascadeTraceParams* cascades = nullptr;
  const GpuLight* lights = nullptr;
  const std::uint32_t* lightRadiance = nullptr;

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#define LIGHT_AT(i) lights[i]
#define LIGHT_RADIANCE(m) lightRadiance[m]
#include "shaders/sdf_trace.glsl"
// light_math.glsl needs sdf_trace.glsl's functions and shade_primary.glsl both: keep the order.
#include "shaders/light_math.glsl"
#include "shaders/shade_primary.glsl"
#undef SDF_PAGE
#undef SDF_DIST_WORD
#undef SDF_ALBEDO
#undef SDF_EMISSION
#undef SDF_CASCADE
#undef LIGHT_AT
#undef LIGHT_RADIANCE
};

// Threads spread over rows (main() of shade_primary.comp, camera_rays.comp, frame_compose.comp).
glm::uvec3 spread(std::uint32_t threads) { return gpu::spreadOverRows(threads); }

// pc.objectsMin/Max: the union of the instances' stack-space AABBs (ObjectInstanceGpu bounds),
// grown by a hundredth of a voxel so rounding in the ray/box clip cannot cut a surface off.
void setObjectBounds(gpu_shared::ShadePushConstants& pc, const ObjectScene* objects) {
  if (!objects || !objects->hasInstances()) return;
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const gpu_shared::ObjectInstanceGpu& i : objects->frame().instances) {
    lo = glm::min(lo, glm::vec3(i.boundsMin));
    hi = glm::max(hi, glm::vec3(i.boundsMax));
  }
  pc.objectsMin = glm::vec4(lo - 0.01f, 0.0f);
  pc.objectsMax = glm::vec4(hi + 0.01f, 0.0f);
}

float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
}  // namespace shade_detail

gpu_shared::ShadePushConstants shadePushConstants(const ShadingSettings& settings,
                                                  std::size_t rayCount, std::size_t lightCount,
                                                  std::uint32_t cascadeCount,
                                                  const gpu_shared::GpuSky& sky,
                                                  double voxelSize0) {
  assert(lightCount <= gpu_shared::kMaxLights);
  gpu_shared::ShadePushConstants pc{};
  pc.counts = glm::uvec4(std::uint32_t(rayCount), std::uint32_t(lightCount), cascadeCount,
                         settings.trace.maxSteps);
  pc.params = glm::vec4(float(voxelSize0), settings.trace.hitEpsilon, settings.shadowEpsilon, 0.0f);
  pc.options = glm::uvec4(settings.direct, settings.shadowSteps, 0u, 0u);
  pc.sky = sky;
  pc.objectsMin = glm::vec4(glm::vec3(1e30f), 0.0f);  // no objects
  pc.objectsMax = glm::vec4(glm::vec3(-1e30f), 0.0f);
  return pc;
}

std::vector<gpu_shared::ShadedHit> shadePrimaryCpu(
    const CascadeStackImage& stack, std::span<const gpu_shared::TraceRay> rays,
    std::span<const gpu_shared::GpuLight> lights, const gpu_shared::GpuSky& sky,
    const ShadingSettings& settings, std::span<const std::uint32_t> lightRadiance,
    std::span<const gpu_shared::PrimarySurface> surfaces) {
  assert(settings.direct != gpu_shared::kShadeDirectCache ||
         lightRadiance.size() >= stack.albedoAtlas->size());
  assert(surfaces.empty() || surfaces.size() == rays.size());
  gpu_shared::ShadePushConstants pc =
      shadePushConstants(settings, rays.size(), lights.size(), std::uint32_t(stack.params.size()),
                         sky, stack.voxelSize0);
  if (!surfaces.empty()) pc.options.z = gpu_shared::kShadePrimaryGiven;
  shade_detail::PrimaryShader shader{stack.pageTables.data(),   stack.distanceAtlas->data(),
                                     stack.albedoAtlas->data(), stack.emissionAtlas->data(),
                                     stack.params.data(),       lights.data(),
                                     lightRadiance.data()};
  std::vector<gpu_shared::ShadedHit> out(rays.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](auto range) {
    auto local = shader;
    for (std::size_t i = range.begin(); i < range.end(); ++i)
      out[i] = surfaces.empty() ? local.shadePrimary(rays[i], pc)
                                : local.shadeGivenSurface(rays[i], surfaces[i], pc);
  });
  return out;
}

PrimaryShadePass::PrimaryShadePass(gpu::Context& context)
    : context_(context),
      pipeline_(
          context, gpu::ShaderId::shade_primary,
          gpu::PipelineDesc{18, sizeof(gpu_shared::ShadePushConstants), glm::uvec3(64, 1, 1)}),
      rays_(context, gpu::StagedBuffer::ToDevice),
      shaded_(context, gpu::StagedBuffer::ToHost),
      surfaces_(context, gpu::StagedBuffer::ToDevice),
      lights_(context, gpu_shared::kMaxLights * sizeof(gpu_shared::GpuLight),
              gpu::BufferKind::Upload),
      noRadiance_(context, 4, gpu::BufferKind::DeviceLocal),
      noSurfaces_(context, sizeof(gpu_shared::PrimarySurface), gpu::BufferKind::DeviceLocal),
      noObjects_(context) {
  // The corner atlas's variant, compiled here rather than in the first frame: the scenes keep
  // their corners by default (GiSettings::cellCorners) wherever they fit.
  pipeline_.get(true);
}

std::vector<gpu_shared::ShadedHit> PrimaryShadePass::run(
    const GpuStackScene& scene, const gpu::Buffer* lightRadiance,
    std::span<const gpu_shared::TraceRay> rays, std::span<const gpu_shared::GpuLight> lights,
    const gpu_shared::GpuSky& sky, const ShadingSettings& settings, double voxelSize0,
    const ObjectScene* objects, std::span<const gpu_shared::PrimarySurface> surfaces) {
  milliseconds_ = 0.0;
  if (rays.empty()) return {};
  const std::size_t rayBytes = rays.size() * sizeof(gpu_shared::TraceRay);
  const std::size_t outBytes = rays.size() * sizeof(gpu_shared::ShadedHit);
  // Every earlier batch was waited for: the host-visible buffers are free to rewrite.
  rays_.reserve(rayBytes);
  shaded_.reserve(outBytes);
  std::memcpy(rays_.host(), rays.data(), rayBytes);
  gpu::CommandBatch batch = context_.beginBatch();
  rays_.recordCopy(batch, rayBytes);
  record(batch, scene, lightRadiance, rays_.device(), shaded_.device(), rays.size(), lights, sky,
         settings, voxelSize0, objects, surfaces);
  shaded_.recordCopy(batch, outBytes);
  batch.submitAndWait();
  for (const auto& t : batch.timings()) milliseconds_ += t.milliseconds;
  std::vector<gpu_shared::ShadedHit> out(rays.size());
  std::memcpy(out.data(), shaded_.host(), outBytes);
  return out;
}

void PrimaryShadePass::record(gpu::CommandBatch& batch, const GpuStackScene& scene,
                              const gpu::Buffer* lightRadiance, const gpu::Buffer& rays,
                              const gpu::Buffer& shaded, std::size_t count,
                              std::span<const gpu_shared::GpuLight> lights,
                              const gpu_shared::GpuSky& sky, const ShadingSettings& settings,
                              double voxelSize0, const ObjectScene* objects,
                              std::span<const gpu_shared::PrimarySurface> surfaces,
                              const gpu::Buffer* deviceSurfaces) {
  assert(settings.direct != gpu_shared::kShadeDirectCache || lightRadiance);
  assert(surfaces.empty() || surfaces.size() == count);
  // Every earlier batch was waited for: the host-visible buffers are free to rewrite.
  const std::size_t surfaceBytes = surfaces.size() * sizeof(gpu_shared::PrimarySurface);
  if (surfaceBytes) {
    surfaces_.reserve(surfaceBytes);
    std::memcpy(surfaces_.host(), surfaces.data(), surfaceBytes);
    surfaces_.recordCopy(batch, surfaceBytes);
  }
  if (!lights.empty())
    std::memcpy(lights_.mapped(), lights.data(), lights.size() * sizeof(gpu_shared::GpuLight));
  gpu_shared::ShadePushConstants pc =
      shadePushConstants(settings, count, lights.size(), scene.cascadeCount(), sky, voxelSize0);
  if (objects && objects->active()) shade_detail::setObjectBounds(pc, objects);
  if (surfaceBytes || deviceSurfaces) pc.options.z = gpu_shared::kShadePrimaryGiven;
  // Records what is bound, as the layout documents; no shader reads it (the variant decides).
  pc.options.w = scene.cellCorners() ? 1u : 0u;
  std::vector<const gpu::Buffer*> bindings = {&rays,
                                              &shaded,
                                              &scene.pageTables(),
                                              &scene.traceAtlas(),
                                              &scene.albedo(),
                                              &scene.emission(),
                                              &scene.params(),
                                              &lights_,
                                              lightRadiance ? lightRadiance : &noRadiance_};
  for (const gpu::Buffer* o :
       objects && objects->active() ? objects->buffers() : noObjects_.buffers())
    bindings.push_back(o);
  bindings.push_back(deviceSurfaces ? deviceSurfaces
                     : surfaceBytes ? &surfaces_.device()
                                    : &noSurfaces_);
  batch.dispatch("shade_primary", pipeline_.get(scene.cellCorners()), bindings, &pc, sizeof pc,
                 shade_detail::spread(pc.counts.x));
}

std::vector<glm::vec3> HdrFrame::final() const {
  std::vector<glm::vec3> out(direct.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = direct[i] + indirect[i];
  return out;
}

std::vector<gpu_shared::TraceRay> cameraRays(const Camera& camera, int width, int height,
                                             const CascadeStackImage& stack) {
  std::vector<gpu_shared::TraceRay> rays =
      primaryRaysFrom(camera, width, height, stack.toStack(camera.position));
  if (stack.params.empty()) return rays;
  // Cascades are nested: the coarsest window holds every other one.
  const gpu_shared::CascadeTraceParams& outer = stack.params.back();
  const glm::vec3 lo(outer.offsetScale), hi = lo + glm::vec3(128.0f * outer.offsetScale.w);
  // Step this far past the entry face, so the start point is inside the window (the window is
  // half-open at its upper faces) yet still in the first cell along the ray.
  const float inset = 1e-3f;
  for (gpu_shared::TraceRay& r : rays) {
    const glm::vec3 o(r.originTMin), d(r.dirTMax);
    float tEnter = r.originTMin.w, tExit = r.dirTMax.w;
    for (int a = 0; a < 3; ++a) {
      if (d[a] == 0.0f) {
        if (o[a] < lo[a] || o[a] >= hi[a]) tEnter = tExit + 1.0f;  // parallel, outside
        continue;
      }
      const float t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
      tEnter = std::max(tEnter, std::min(t0, t1));
      tExit = std::min(tExit, std::max(t0, t1));
    }
    const bool inside =
        o.x >= lo.x && o.y >= lo.y && o.z >= lo.z && o.x < hi.x && o.y < hi.y && o.z < hi.z;
    if (!inside) r.originTMin.w = tEnter <= tExit ? tEnter + inset : r.dirTMax.w * 2.0f;
  }
  return rays;
}

std::vector<gpu_shared::ProbeQuery> probeQueries(std::span<const gpu_shared::ShadedHit> shaded,
                                                 std::span<const gpu_shared::TraceRay> rays,
                                                 std::vector<std::uint32_t>& pixels) {
  assert(shaded.size() == rays.size());
  std::vector<gpu_shared::ProbeQuery> queries;
  pixels.clear();
  for (std::size_t i = 0; i < shaded.size(); ++i) {
    const gpu_shared::ShadedHit& h = shaded[i];
    if (!(h.flags & gpu_shared::kHitFlagHit)) continue;
    const glm::vec3 dir(rays[i].dirTMax);
    // A given (rasterized) surface's query starts where its shadow rays do, outside the SDF's
    // surface (ShadedHit::direct.w; 0 for traced hits).
    const glm::vec3 hit =
        glm::vec3(rays[i].originTMin) + dir * h.normalT.w + glm::vec3(h.normalT) * h.direct.w;
    gpu_shared::ProbeQuery q{};
    q.position = glm::vec4(hit, 0.0f);  // w = 0: blend across all cascades
    q.normal = glm::vec4(glm::vec3(h.normalT), 0.0f);
    q.view = glm::vec4(-dir, 0.0f);
    queries.push_back(q);
    pixels.push_back(std::uint32_t(i));
  }
  return queries;
}

HdrFrame composeFrame(std::span<const gpu_shared::ShadedHit> shaded, int width, int height,
                      std::span<const std::uint32_t> pixels,
                      std::span<const glm::vec3> indirectIrradiance) {
  assert(shaded.size() == std::size_t(width) * height);
  assert(indirectIrradiance.empty() || indirectIrradiance.size() == pixels.size());
  HdrFrame f;
  f.width = width;
  f.height = height;
  f.direct.resize(shaded.size());
  f.indirect.assign(shaded.size(), glm::vec3(0.0f));
  for (std::size_t i = 0; i < shaded.size(); ++i) {
    f.direct[i] = glm::vec3(shaded[i].direct);
    if (shaded[i].flags & gpu_shared::kHitFlagHit) ++f.hits;
    if (shaded[i].flags & gpu_shared::kShadeFlagObject) ++f.objectHits;
  }
  constexpr float kInvPi = 0.3183098861837907f;
  for (std::size_t q = 0; q < indirectIrradiance.size(); ++q) {
    const std::uint32_t p = pixels[q];
    const glm::vec4 a = gpu_shared::unpackAlbedo(shaded[p].albedo);
    const glm::vec3 albedo(shade_detail::srgbToLinear(a.r), shade_detail::srgbToLinear(a.g),
                           shade_detail::srgbToLinear(a.b));
    f.indirect[p] = albedo * kInvPi * indirectIrradiance[q];
  }
  return f;
}

CascadeStackImage stackImageOf(const CascadeImage& cascade) {
  CascadeStackImage img;
  img.pageTables = cascade.pageTable;
  img.distanceAtlas = &cascade.distanceAtlas;
  img.albedoAtlas = &cascade.albedoAtlas;
  img.emissionAtlas = &cascade.emissionAtlas;
  gpu_shared::CascadeTraceParams p{};
  p.offsetScale = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  p.toroidal = cascade.toroidalOffset();  // w = 0: the first (only) page table
  img.params = {p};
  img.voxelSize0 = cascade.voxelSize;
  img.cascade0MinWorld = cascade.toWorld(glm::vec3(0.0f));
  img.originBricks = {cascade.originBrick};
  return img;
}

SceneLights defaultSceneLights(glm::vec3 sunTravelDirection, float sunIrradiance,
                               glm::vec3 skyZenith, glm::vec3 skyHorizon) {
  SceneLights l;
  SceneLight sun;
  sun.type = SceneLight::Type::Sun;
  sun.direction = glm::normalize(sunTravelDirection);
  sun.color = glm::vec3(1.0f, 0.96f, 0.88f);  // a little warmer than the sky
  sun.intensity = sunIrradiance;
  sun.shadowSharpness = 24.0f;
  if (sunIrradiance > 0.0f) l.lights.push_back(sun);
  l.sky.zenith = skyZenith;
  l.sky.horizon = skyHorizon;
  return l;
}

// renderPicture's passes and per-pixel device buffers (grown on demand, never shrunk).
struct GiRenderer::PicturePasses {
  explicit PicturePasses(gpu::Context& context)
      : context(context),
        rays(context, gpu::ShaderId::camera_rays,
             gpu::PipelineDesc{1, sizeof(gpu_shared::CameraRaysPush), glm::uvec3(64, 1, 1)}),
        compose(context, gpu::ShaderId::frame_compose,
                gpu::PipelineDesc{3 + GiSystem::kSampleBindingCount + 8,
                                  sizeof(gpu_shared::FrameComposePush), glm::uvec3(64, 1, 1)}),
        noObjects(context) {}
  void reserve(std::size_t pixels) {
    if (pixels <= capacity) return;
    rayBuffer =
        gpu::Buffer(context, pixels * sizeof(gpu_shared::TraceRay), gpu::BufferKind::DeviceLocal);
    shaded =
        gpu::Buffer(context, pixels * sizeof(gpu_shared::ShadedHit), gpu::BufferKind::DeviceLocal);
    picture = gpu::Buffer(context, pixels * 4, gpu::BufferKind::DeviceLocal);
    readback = gpu::Buffer(context, pixels * 4, gpu::BufferKind::Readback);
    capacity = pixels;
  }
  // The raster primary's visibility buffer and resolved surfaces (allocated on first use).
  void reserveRaster(std::size_t pixels) {
    if (pixels <= rasterCapacity) return;
    visibility = gpu::Buffer(context, pixels * 12, gpu::BufferKind::DeviceLocal);
    surfaces = gpu::Buffer(context, pixels * sizeof(gpu_shared::PrimarySurface),
                           gpu::BufferKind::DeviceLocal);
    rasterCapacity = pixels;
  }
  gpu::Context& context;
  gpu::ComputePipeline rays, compose;
  NoObjectsBindings noObjects;  // bound at 11-18 when there are no objects
  gpu::Buffer rayBuffer, shaded, picture, readback, visibility, surfaces;
  std::size_t rasterCapacity = 0;
  std::size_t capacity = 0;
};

GiRenderer::GiRenderer(gpu::Context& context, const GiRendererOptions& options,
                       std::uint32_t cascades)
    : context_(context),
      options_(options),
      relight_(options.settings.light.relightPageBudget),
      shade_(context) {
  if (options.gi) {
    gi_ = std::make_unique<GiSystem>(context, options.settings, cascades);
  } else {
    scene_ = std::make_unique<GpuStackScene>(context);
    if (options.shading.direct == gpu_shared::kShadeDirectCache)
      light_ = std::make_unique<LightCache>(context, options.settings.light);
  }
}

GiRenderer::~GiRenderer() = default;

const GpuStackScene& GiRenderer::scene() const { return gi_ ? gi_->scene() : *scene_; }

std::uint32_t GiRenderer::reserveAtlasSlots(std::uint32_t slots) {
  return gi_ ? gi_->reserveAtlasSlots(slots) : scene_->reserveAtlas(slots);
}

std::uint32_t GiRenderer::shrinkAtlasSlots(std::uint32_t slots) {
  return gi_ ? gi_->shrinkAtlasSlots(slots) : scene_->shrinkAtlas(slots);
}

const ObjectScene* GiRenderer::objectScene() const {
  if (!objectLibrary_) return nullptr;
  return gi_ ? &gi_->objects() : objects_.get();
}

void GiRenderer::setPrimaryMesh(const TriangleScene* scene) {
  raster_ = scene ? std::make_unique<MeshViewRaster>(context_, *scene) : nullptr;
}

void GiRenderer::setObjects(const ObjectLibrary* library, InstanceSet* instances) {
  objectLibrary_ = library;
  instances_ = library ? instances : nullptr;
  if (gi_) {
    gi_->setObjects(library, instances_);
  } else if (library && !objects_) {
    objects_ = std::make_unique<ObjectScene>(context_, options_.settings.objects);
  }
}

const gpu::Buffer* GiRenderer::lightRadiance() const {
  if (gi_) return &gi_->lightCache().radianceBuffer();
  return light_ ? &light_->radianceBuffer() : nullptr;
}

std::size_t GiRenderer::probeDeviceBytes() const { return gi_ ? gi_->probes().deviceBytes() : 0; }

GiFrameStats GiRenderer::updateDirectOnly(const CascadeStackImage& image,
                                          const SceneLights& lights) {
  GiFrameStats stats;
  // Objects as GiSystem::run handles them: rebuild for this stack, relight the light cache's
  // pages their old and new poses shadow, consume the change record.
  std::vector<std::uint32_t> shadowed;
  const auto gpuLights = toGpu(lights.lights, image);
  if (instances_) {
    objects_->update(*objectLibrary_, *instances_, image);
    for (const auto& t : objects_->lastTimings()) stats.objectMilliseconds += t.milliseconds;
    stats.objectInstances = std::uint32_t(instances_->size());
    if (light_) {
      shadowed = objectShadowPages(image, objects_->frame().changedBoxes, gpuLights);
      stats.objectPagesRelit = std::uint32_t(shadowed.size());
    }
    instances_->endFrame();
  }
  if (light_) {
    const bool lightsChanged = lights.version != lightsVersion_;
    lightsVersion_ = lights.version;
    const std::vector<std::uint32_t> dirty = relight_.select(
        image, lightDirtyPages(previous_.get(), image, false), shadowed, lightsChanged);
    stats.relight = relight_.stats();
    light_->update(*scene_, gpuLights, toGpu(lights.sky), dirty, image.voxelSize0,
                   instances_ ? objects_.get() : nullptr);
    stats.pagesRelit = light_->pagesRelitLastUpdate();
    for (const auto& t : light_->lastTimings()) stats.lightMilliseconds += t.milliseconds;
    previous_ = std::make_unique<CascadeStackImage>(image);
  }
  return stats;
}

GiFrameStats GiRenderer::update(const CascadeStackImage& image, const SceneLights& lights,
                                const probe::ProbeFrameInputs& inputs, std::uint64_t frame) {
  times_.probePasses.clear();
  if (gi_) {
    times_.gi = gi_->update(image, lights, inputs, frame);
    times_.probePasses = gi_->probes().lastTimings();
  } else {
    scene_->uploadAll(image);
    times_.gi = updateDirectOnly(image, lights);
  }
  return times_.gi;
}

GiFrameStats GiRenderer::update(const CascadeStack& stack, std::span<const std::uint32_t> dirty,
                                const SceneLights& lights, const probe::ProbeFrameInputs& inputs,
                                std::uint64_t frame) {
  times_.probePasses.clear();
  if (gi_) {
    times_.gi = gi_->update(stack, dirty, lights, inputs, frame);
    times_.probePasses = gi_->probes().lastTimings();
  } else {
    scene_->sync(stack, dirty);
    times_.gi =
        light_ || instances_ ? updateDirectOnly(stack.stackImage(), lights) : GiFrameStats{};
  }
  return times_.gi;
}

Image8 GiRenderer::renderPicture(const Camera& camera, int width, int height,
                                 const CascadeStackImage& image, const SceneLights& lights,
                                 const PictureSettings& settings) {
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  if (!picture_) picture_ = std::make_unique<PicturePasses>(context_);
  picture_->reserve(pixels);
  if (raster_) picture_->reserveRaster(pixels);
  gpu_shared::CameraRaysPush rays =
      cameraRaysPush(camera, width, height, image.toStack(camera.position));
  if (!image.params.empty()) {  // cascades are nested: the coarsest window holds the others
    const gpu_shared::CascadeTraceParams& outer = image.params.back();
    const glm::vec3 lo(outer.offsetScale);
    rays.windowLo = glm::vec4(lo, 0.0f);
    rays.windowHi = glm::vec4(lo + glm::vec3(128.0f * outer.offsetScale.w), 1.0f);
  }
  gpu_shared::FrameComposePush compose{};
  compose.size = glm::uvec4(std::uint32_t(width), std::uint32_t(height), settings.mode,
                            (gi_ ? gpu_shared::kFrameProbesBound : 0u) |
                                (settings.indirect ? gpu_shared::kFrameAddIndirect : 0u));
  compose.params =
      glm::vec4(std::exp2(settings.exposureStops), std::exp2(settings.indirectStops), 0.0f, 0.0f);
  PicturePasses& p = *picture_;
  std::vector<const gpu::Buffer*> bindings = {&p.rayBuffer, &p.shaded, &p.picture};
  if (gi_) {
    for (const gpu::Buffer* b : gi_->sampleBuffers()) bindings.push_back(b);
  } else {
    bindings.resize(bindings.size() + GiSystem::kSampleBindingCount, &p.shaded);  // never read
  }
  const ObjectScene* objects = objectScene();
  for (const gpu::Buffer* o :
       objects && objects->active() ? objects->buffers() : p.noObjects.buffers())
    bindings.push_back(o);
  gpu::CommandBatch batch = context_.beginBatch();
  if (raster_) {  // the surfaces stay on the device: rasterized, then resolved there
    const double pixelAngle = cameraPixelAngle(camera, height);
    raster_->record(batch, viewRasterPush(camera, width, height), width, height, p.visibility);
    raster_->recordResolve(batch, width, height, camera.position, pixelAngle,
                           image.cascade0MinWorld, image.voxelSize0, p.visibility, p.surfaces);
  }
  batch.dispatch("camera_rays", p.rays, {&p.rayBuffer}, &rays, sizeof rays,
                 shade_detail::spread(std::uint32_t(pixels)));
  shade_.record(batch, scene(), lightRadiance(), p.rayBuffer, p.shaded, pixels,
                toGpu(lights.lights, image), toGpu(lights.sky), options_.shading, image.voxelSize0,
                objectScene(), {}, raster_ ? &p.surfaces : nullptr);
  batch.dispatch("frame_compose", p.compose, bindings, &compose, sizeof compose,
                 shade_detail::spread(std::uint32_t(pixels)));
  batch.copy(p.picture, p.readback, pixels * 4);
  batch.submitAndWait();
  times_.shadeMilliseconds = times_.sampleMilliseconds = times_.rasterMilliseconds = 0.0;
  for (const gpu::PassTiming& t : batch.timings()) {
    if (t.name == "raster primary" || t.name == "raster_resolve")
      times_.rasterMilliseconds += t.milliseconds;
    if (t.name == "frame_compose") times_.sampleMilliseconds += t.milliseconds;
    if (t.name == "camera_rays" || t.name == "shade_primary")
      times_.shadeMilliseconds += t.milliseconds;
  }
  Image8 out{width, height, std::vector<std::uint8_t>(pixels * 3)};
  const auto* rgba = static_cast<const std::uint8_t*>(p.readback.mapped());
  for (std::size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < 3; ++c) out.rgb[3 * i + c] = rgba[4 * i + c];
  return out;
}

ShadedView GiRenderer::shade(const Camera& camera, int width, int height,
                             const CascadeStackImage& image, const SceneLights& lights) {
  ShadedView v;
  v.width = width;
  v.height = height;
  v.rays = cameraRays(camera, width, height, image);
  std::vector<gpu_shared::PrimarySurface> surfaces;
  times_.rasterMilliseconds = 0.0;
  if (raster_) {
    const VisibilityImage visible =
        raster_->render(viewRasterPush(camera, width, height), width, height);
    times_.rasterMilliseconds = raster_->lastMilliseconds();
    const double pixelAngle = cameraPixelAngle(camera, height);
    surfaces =
        resolvePrimarySurfaces(raster_->scene(), raster_->pyramid(), visible, camera.position,
                               pixelAngle, image.cascade0MinWorld, image.voxelSize0);
  }
  v.shaded =
      shade_.run(scene(), lightRadiance(), v.rays, toGpu(lights.lights, image), toGpu(lights.sky),
                 options_.shading, image.voxelSize0, objectScene(), surfaces);
  times_.shadeMilliseconds = shade_.lastMilliseconds();
  v.queries = probeQueries(v.shaded, v.rays, v.pixels);
  return v;
}

HdrFrame GiRenderer::finish(const ShadedView& view) {
  times_.sampleMilliseconds = 0.0;
  std::vector<glm::vec3> irradiance;
  if (gi_ && !view.queries.empty()) {  // (no queries: no sample pass, no time of its own)
    irradiance = gi_->irradiance(view.queries);
    times_.sampleMilliseconds = gi_->lastSampleMilliseconds();
  }
  return composeFrame(view.shaded, view.width, view.height, view.pixels, irradiance);
}

glm::vec3 GiRenderer::meanIrradiance(std::span<const gpu_shared::ProbeQuery> queries) {
  if (!gi_ || queries.empty()) return glm::vec3(0.0f);
  const auto e = gi_->irradiance(queries);
  glm::dvec3 sum(0.0);
  for (const glm::vec3& v : e) sum += glm::dvec3(v);
  return glm::vec3(sum / double(e.size()));
}

}  // namespace sdfstream
