#include "gi/object_scene_cpu.h"

namespace sdfstream {
namespace object_detail {
using namespace glm;
using namespace gpu_shared;

// The GLSL becomes member functions reading this object's arrays through the OBJ_* macros.
struct ObjectPasses {
  const ObjectFrameGpu* framePtr = nullptr;
  const ObjectMeshGpu* meshes = nullptr;
  const ObjectInstanceGpu* instances = nullptr;
  const ObjectRegionGpu* regions = nullptr;
  const std::uint32_t* list = nullptr;
  const float* dist = nullptr;
  const glm::uvec2* mat = nullptr;

#define SDF_PRECISE
#define OBJ_FRAME (*framePtr)
#define OBJ_MESH(m) meshes[m]
#define OBJ_INSTANCE(i) instances[i]
#define OBJ_REGION(i) regions[i]
#define OBJ_LIST(i) list[i]
#define OBJ_DIST(i) dist[i]
#define OBJ_MAT(i) mat[i]
#include "shaders/object_trace.glsl"
#undef SDF_PRECISE
};

ObjectTraceHit toHit(const ObjectPasses::ObjectHit& h) {
  ObjectTraceHit out{};
  out.normalT = vec4(h.normal, h.t);
  out.instance = h.instance;
  out.albedo = h.albedo;
  out.emission = h.emission;
  out.steps = h.steps;
  out.tried = h.instancesTried;
  return out;
}
}  // namespace object_detail

namespace gs = gpu_shared;
using object_detail::ObjectPasses;

namespace {
ObjectPasses passesOf(const ObjectAtlasData& atlas, const ObjectFrameData& frame,
                      const std::vector<gs::ObjectRegionGpu>& regions,
                      const std::vector<std::uint32_t>& flat) {
  ObjectPasses p;
  p.framePtr = &frame.frame;
  p.meshes = atlas.meshes.data();
  p.instances = frame.instances.data();
  p.regions = regions.data();
  p.list = flat.data();
  p.dist = atlas.distance.data();
  p.mat = atlas.material.data();
  return p;
}
}  // namespace

ObjectSceneCpu::ObjectSceneCpu(const ObjectLibrary& library, const InstanceSet& instances,
                               const CascadeStackImage& stack, const ObjectSceneSettings& settings)
    : atlas_(buildObjectAtlas(library)),
      frame_(buildObjectFrame(library, instances, stack, settings)) {
  const std::uint32_t cascades = frame_.frame.counts.y;
  const std::size_t regionCount = std::size_t(cascades) * gs::kRegionsPerCascade;
  lists_.assign(regionCount, {});
  regions_.assign(regionCount, gs::ObjectRegionGpu{});
  ObjectPasses p = passesOf(atlas_, frame_, regions_, flat_);
  for (std::uint32_t c = 0; c < cascades; ++c) {
    const glm::vec4 ro = frame_.frame.regionOrigin[c];
    for (std::uint32_t r = 0; r < gs::kRegionsPerCascade; ++r) {
      const glm::vec3 lo = glm::vec3(ro) + glm::vec3(r % 8, (r / 8) % 8, r / 64) * ro.w;
      const std::uint32_t g = c * gs::kRegionsPerCascade + r;
      std::copy(std::begin(frame_.regions[g].wake), std::end(frame_.regions[g].wake),
                std::begin(regions_[g].wake));
      regions_[g].moved = frame_.regions[g].moved;
      for (std::uint32_t i = 0; i < frame_.instances.size(); ++i) {
        const gs::ObjectInstanceGpu& inst = frame_.instances[i];
        const float voxel = ro.w / 16.0f;
        if (c > 0 && inst.boundsMax.w < settings.sizeRule * voxel) continue;
        const glm::uvec4 d = atlas_.meshes[inst.info.x].dimsOffset;
        if (!p.objObbOverlapsBox(inst, glm::uvec3(d), lo, lo + glm::vec3(ro.w))) continue;
        lists_[g].push_back(i);
        const auto sub =
            p.objSubCellRange(glm::vec3(inst.boundsMin), glm::vec3(inst.boundsMax), lo, ro.w);
        for (int z = sub.lo.z; z <= sub.hi.z; ++z)
          for (int y = sub.lo.y; y <= sub.hi.y; ++y)
            regions_[g].occupancy[p.objOccupancyWord(y, z)] |= p.objRowMask(sub.lo.x, sub.hi.x)
                                                               << p.objOccupancyShift(y);
      }
      regions_[g].start = std::uint32_t(flat_.size());
      regions_[g].count = std::uint32_t(lists_[g].size());
      flat_.insert(flat_.end(), lists_[g].begin(), lists_[g].end());
    }
  }
}

bool ObjectSceneCpu::wakes(glm::vec3 stackPoint, std::uint32_t cascade) const {
  ObjectPasses p = passesOf(atlas_, frame_, regions_, flat_);
  return p.objMovedNear(stackPoint, cascade);
}

gs::ObjectTraceHit ObjectSceneCpu::traceRegions(const gs::TraceRay& ray) const {
  ObjectPasses p = passesOf(atlas_, frame_, regions_, flat_);
  return object_detail::toHit(p.objTraceRegions(glm::vec3(ray.originTMin), glm::vec3(ray.dirTMax),
                                                ray.originTMin.w, ray.dirTMax.w, 0u));
}

gs::ObjectTraceHit ObjectSceneCpu::traceAll(const gs::TraceRay& ray) const {
  ObjectPasses p = passesOf(atlas_, frame_, regions_, flat_);
  return object_detail::toHit(p.objTraceAll(glm::vec3(ray.originTMin), glm::vec3(ray.dirTMax),
                                            ray.originTMin.w, ray.dirTMax.w));
}

}  // namespace sdfstream
