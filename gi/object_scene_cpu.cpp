#include "gi/object_scene_cpu.h"

#include <algorithm>

#include "shaders/shared/color_codec.h"

namespace sdfstream {
namespace object_detail {
using namespace glm;
using namespace gpu_shared;

// The objects' buffers, named as the OBJ_* macros below read them.
struct ObjectBindings {
  const ObjectFrameGpu* framePtr = nullptr;
  const ObjectMeshGpu* meshes = nullptr;
  const ObjectInstanceGpu* instances = nullptr;
  const ObjectRegionGpu* regions = nullptr;
  const glm::uvec4* list = nullptr;
  const float* dist = nullptr;
  const glm::uvec2* mat = nullptr;
};

// The GLSL becomes member functions reading this object's arrays through the OBJ_* macros.
struct ObjectPasses : ObjectBindings {
  ObjectWalkCounts* walkCounts = nullptr;  // counted when set
  const CardGpu* cards = nullptr;
  const CardTexelGpu* cardTexels = nullptr;  // indexed from the table's start, as on the GPU
  std::uint32_t cardTableWords = 0;
  const std::uint32_t* cardLight = nullptr;

#define SDF_PRECISE
#define OBJ_FRAME (*framePtr)
#define OBJ_MESH(m) meshes[m]
#define OBJ_INSTANCE(i) instances[i]
#define OBJ_REGION(i) regions[i]
#define OBJ_LIST(i) list[i]
#define OBJ_DIST(i) dist[i]
#define OBJ_MAT(i) mat[i]
#define OBJ_CARD(i) cards[i]
#define OBJ_CARD_TEXEL(i) cardTexels[(i)-cardTableWords]
#define OBJ_CARD_LIGHT(i) cardLight[i]
#define OBJ_COUNT(counter) \
  if (walkCounts) ++walkCounts->counter
#include "shaders/card_lookup.glsl"
#include "shaders/card_math.glsl"
#include "shaders/object_trace.glsl"
#undef SDF_PRECISE
#undef OBJ_COUNT
};

// The card light pass: the static stack's SDF macros and the objects' together, as
// card_light.comp binds them (its shadow rays see both).
struct CardLightPasses : ObjectBindings {
  const CardTexelGpu* cardTexels = nullptr;  // indexed from the table's start, as on the GPU
  std::uint32_t cardTableWords = 0;
  const std::uint32_t* pageTable = nullptr;
  const std::uint32_t* distanceAtlas = nullptr;
  const std::uint32_t* albedoAtlas = nullptr;
  const std::uint32_t* emissionAtlas = nullptr;
  const CascadeTraceParams* cascades = nullptr;
  const GpuLight* lights = nullptr;

#define SDF_PRECISE
#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#define LIGHT_AT(i) lights[i]
#define OBJ_CARD_TEXEL(i) cardTexels[(i)-cardTableWords]
#include "shaders/object_trace.glsl"
#include "shaders/sdf_trace.glsl"
// light_math.glsl and card_light.glsl need the functions above: keep this order.
#include "shaders/card_light.glsl"
#include "shaders/card_math.glsl"
#include "shaders/light_math.glsl"
#undef SDF_PRECISE
#undef SDF_PAGE
#undef SDF_DIST_WORD
#undef SDF_ALBEDO
#undef SDF_EMISSION
#undef SDF_CASCADE
#undef LIGHT_AT
#undef OBJ_CARD_TEXEL
};

ObjectTraceHit toHit(ObjectPasses& p, const ObjectPasses::ObjectHit& h, glm::vec3 o, glm::vec3 d) {
  ObjectTraceHit out{};
  out.cardLight = 0u;
  out.cardWeight = glm::floatBitsToUint(0.0f);
  out.cardTexel = kNoCardLight;
  if (h.t >= 0.0f && p.cardLight) {
    const ObjectPasses::CardLookup card = p.cardLookup(h.instance, o + d * h.t, h.normal);
    out.cardLight = packRgb9e5(card.radiance);
    out.cardWeight = glm::floatBitsToUint(card.weight);
    out.cardTexel = card.texel;
  }
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
template <typename Passes>
Passes passesOf(const ObjectAtlasData& atlas, const ObjectFrameData& frame,
                const std::vector<gs::ObjectRegionGpu>& regions,
                const std::vector<glm::uvec4>& flat) {
  Passes p;
  p.framePtr = &frame.frame;
  p.meshes = atlas.meshes.data();
  p.instances = frame.instances.data();
  p.regions = regions.data();
  p.list = flat.data();
  p.dist = atlas.distance.data();
  p.mat = atlas.material.data();
  return p;
}

glm::uvec4 entryOf(ObjectPasses& p, std::uint32_t i, glm::vec3 regionLo, float edge) {
  const gs::ObjectInstanceGpu& inst = p.instances[i];
  return p.objListEntry(i, glm::vec3(inst.boundsMin), glm::vec3(inst.boundsMax), regionLo, edge);
}

void bindCards(ObjectPasses& p, const std::vector<gs::CardGpu>& table,
               const std::vector<gs::CardTexelGpu>& texels,
               const std::vector<std::uint32_t>& light) {
  if (table.empty()) return;
  p.cards = table.data();
  p.cardTexels = texels.data();
  p.cardTableWords = std::uint32_t(table.size()) * 4u;
  p.cardLight = light.data();
}
}  // namespace

ObjectSceneCpu::ObjectSceneCpu(const ObjectLibrary& library, const InstanceSet& instances,
                               const CascadeStackImage& stack, const ObjectSceneSettings& settings)
    : atlas_(buildObjectAtlas(library)),
      frame_(buildObjectFrame(library, instances, stack, settings)) {
  const std::uint32_t cascades = frame_.frame.counts.y;
  const std::size_t regionCount = std::size_t(cascades) * gs::kRegionsPerCascade;
  // Lists the host placed (no sub-cell lists this frame): as on the GPU, no instance is wide and
  // every one marks its sub-cells.
  const bool hostPlaced = frame_.subListCapacity == 0;
  lists_.assign(regionCount, {});
  regions_.assign(regionCount, gs::ObjectRegionGpu{});
  ObjectPasses p = passesOf<ObjectPasses>(atlas_, frame_, regions_, flat_);
  // Per region: the instances touching each sub-cell (bit order), gathered before the layout.
  std::vector<std::vector<std::vector<std::uint32_t>>> subLists(regionCount);
  std::vector<glm::vec3> regionLo(regionCount);
  for (std::uint32_t c = 0; c < cascades; ++c) {
    const glm::vec4 ro = frame_.frame.regionOrigin[c];
    for (std::uint32_t r = 0; r < gs::kRegionsPerCascade; ++r) {
      const glm::vec3 lo = glm::vec3(ro) + glm::vec3(r % 8, (r / 8) % 8, r / 64) * ro.w;
      const std::uint32_t g = c * gs::kRegionsPerCascade + r;
      regionLo[g] = lo;
      std::copy(std::begin(frame_.regions[g].wake), std::end(frame_.regions[g].wake),
                std::begin(regions_[g].wake));
      regions_[g].moved = frame_.regions[g].moved;
      std::vector<std::uint32_t> wide, narrow;
      for (std::uint32_t i = 0; i < frame_.instances.size(); ++i) {
        const gs::ObjectInstanceGpu& inst = frame_.instances[i];
        const float voxel = ro.w / 16.0f;
        if (c > 0 && inst.boundsMax.w < settings.sizeRule * voxel) continue;
        // The AABB first (it holds the OBB, so a miss is a miss), then the exact SAT test.
        const glm::vec3 hi = lo + glm::vec3(ro.w);
        if (glm::any(glm::lessThan(glm::vec3(inst.boundsMax), lo)) ||
            glm::any(glm::greaterThan(glm::vec3(inst.boundsMin), hi)))
          continue;
        const glm::uvec4 d = atlas_.meshes[inst.info.x].dimsOffset;
        if (!p.objObbOverlapsBox(inst, glm::uvec3(d), lo, hi)) continue;
        const auto sub =
            p.objSubCellRange(glm::vec3(inst.boundsMin), glm::vec3(inst.boundsMax), lo, ro.w);
        if (!hostPlaced && p.objSubCellCount(sub) > gs::kSubListMaxCells) {
          wide.push_back(i);
          continue;
        }
        narrow.push_back(i);
        if (subLists[g].empty()) subLists[g].resize(512);
        for (int z = sub.lo.z; z <= sub.hi.z; ++z)
          for (int y = sub.lo.y; y <= sub.hi.y; ++y) {
            regions_[g].occupancy[p.objOccupancyWord(y, z)] |= p.objRowMask(sub.lo.x, sub.hi.x)
                                                               << p.objOccupancyShift(y);
            for (int x = sub.lo.x; x <= sub.hi.x; ++x) subLists[g][x + 8 * y + 64 * z].push_back(i);
          }
      }
      regions_[g].wide = std::uint32_t(wide.size());
      regions_[g].count = std::uint32_t(wide.size() + narrow.size());
      lists_[g] = wide;
      lists_[g].insert(lists_[g].end(), narrow.begin(), narrow.end());
      std::sort(lists_[g].begin(), lists_[g].end());
      wide.insert(wide.end(), narrow.begin(), narrow.end());  // the entries' order on the GPU
      regions_[g].start = std::uint32_t(flat_.size());
      for (std::uint32_t i : wide) flat_.push_back(entryOf(p, i, regionLo[g], ro.w));
    }
  }
  // The sub-cell headers of every region (in rank order), then their entries; as the GPU's scan,
  // a region whose headers or entries would pass the capacity (frame_.subListCapacity) keeps
  // none (kNoSubLists).
  const std::size_t headerBase = flat_.size();
  const std::size_t capacity = frame_.subListCapacity;
  std::size_t headers = 0, entries = 0;
  for (std::size_t g = 0; g < regionCount; ++g) {
    std::uint32_t* occupancy = regions_[g].occupancy;
    for (std::uint32_t w = 0; w < gs::kOccupancyWords; w += 2)
      regions_[g].rank[w / 2] =
          p.objOccupiedBefore(occupancy, w) | p.objOccupiedBefore(occupancy, w + 1) << 16;
    const std::uint32_t rank = p.objOccupiedBefore(occupancy, gs::kOccupancyWords);
    regions_[g].occupiedBounds = p.objOccupiedBounds(regions_[g].occupancy);
    std::size_t own = 0;
    for (const auto& list : subLists[g]) own += list.size();
    const bool fits = capacity > 0 && headers + rank <= capacity && entries + own <= capacity;
    regions_[g].subBase = fits ? std::uint32_t(headerBase + headers) : gs::kNoSubLists;
    if (!fits) subLists[g].clear();
    headers += rank;
    entries += own;
  }
  flat_.resize(headerBase + headers, glm::uvec4(0u));
  for (std::size_t g = 0; g < regionCount; ++g) {
    const glm::vec4 ro = frame_.frame.regionOrigin[g / gs::kRegionsPerCascade];
    regions_[g].subStart = std::uint32_t(flat_.size());
    for (std::uint32_t bit = 0, rank = 0; bit < 512 && !subLists[g].empty(); ++bit) {
      if (subLists[g][bit].empty()) continue;
      flat_[regions_[g].subBase + rank++] =
          glm::uvec4(std::uint32_t(flat_.size()), std::uint32_t(subLists[g][bit].size()), 0u, 0u);
      for (std::uint32_t i : subLists[g][bit]) flat_.push_back(entryOf(p, i, regionLo[g], ro.w));
    }
  }
}

std::vector<std::uint32_t> ObjectSceneCpu::subCellInstances(std::uint32_t region,
                                                            std::uint32_t bit) const {
  std::vector<std::uint32_t> out;
  const gs::ObjectRegionGpu& r = regions_.at(region);
  if ((r.occupancy[bit / 32] >> (bit % 32) & 1u) == 0 || r.subBase == gs::kNoSubLists) return out;
  ObjectPasses p = passesOf<ObjectPasses>(atlas_, frame_, regions_, flat_);
  const glm::uvec4 header = flat_.at(r.subBase + p.objSubRank(region, bit));
  for (std::uint32_t k = 0; k < header.y; ++k) out.push_back(flat_.at(header.x + k).x);
  std::sort(out.begin(), out.end());
  return out;
}

bool ObjectSceneCpu::wakes(glm::vec3 stackPoint, std::uint32_t cascade) const {
  ObjectPasses p = passesOf<ObjectPasses>(atlas_, frame_, regions_, flat_);
  return p.objMovedNear(stackPoint, cascade);
}

void ObjectSceneCpu::setCards(std::vector<gs::CardGpu> table, std::vector<gs::CardTexelGpu> texels,
                              std::vector<std::uint32_t> light,
                              std::span<const std::uint32_t> instanceLightBases) {
  cardTable_ = std::move(table);
  cardTexels_ = std::move(texels);
  cardLight_ = std::move(light);
  for (std::size_t i = 0; i < frame_.instances.size() && i < instanceLightBases.size(); ++i)
    frame_.instances[i].info.w = instanceLightBases[i];
}

gs::ObjectTraceHit ObjectSceneCpu::traceRegions(const gs::TraceRay& ray,
                                                ObjectWalkCounts* counts) const {
  ObjectPasses p = passesOf<ObjectPasses>(atlas_, frame_, regions_, flat_);
  p.walkCounts = counts;
  bindCards(p, cardTable_, cardTexels_, cardLight_);
  const glm::vec3 o(ray.originTMin), d(ray.dirTMax);
  return object_detail::toHit(p, p.objTraceRegions(o, d, ray.originTMin.w, ray.dirTMax.w, 0u), o,
                              d);
}

bool ObjectSceneCpu::occluded(const gs::TraceRay& ray) const {
  ObjectPasses p = passesOf<ObjectPasses>(atlas_, frame_, regions_, flat_);
  return p.objOccluded(glm::vec3(ray.originTMin), glm::vec3(ray.dirTMax), ray.originTMin.w,
                       ray.dirTMax.w);
}

gs::ObjectTraceHit ObjectSceneCpu::traceAll(const gs::TraceRay& ray) const {
  ObjectPasses p = passesOf<ObjectPasses>(atlas_, frame_, regions_, flat_);
  bindCards(p, cardTable_, cardTexels_, cardLight_);
  const glm::vec3 o(ray.originTMin), d(ray.dirTMax);
  return object_detail::toHit(p, p.objTraceAll(o, d, ray.originTMin.w, ray.dirTMax.w), o, d);
}

std::vector<std::uint32_t> ObjectSceneCpu::cardLight(std::uint32_t instance,
                                                     const CascadeStackImage& stack,
                                                     std::span<const gs::GpuLight> lights,
                                                     const LightCacheSettings& settings) const {
  std::vector<std::uint32_t> out;
  if (cardTable_.empty() || instance >= frame_.instances.size()) return out;
  auto p = passesOf<object_detail::CardLightPasses>(atlas_, frame_, regions_, flat_);
  p.pageTable = stack.pageTables.data();
  p.distanceAtlas = stack.distanceAtlas->data();
  p.albedoAtlas = stack.albedoAtlas->data();
  p.emissionAtlas = stack.emissionAtlas->data();
  p.cascades = stack.params.data();
  p.lights = lights.data();
  const gs::LightCachePushConstants pc =
      lightCachePushConstants(settings, 1, std::uint32_t(lights.size()),
                              std::uint32_t(stack.params.size()), gs::GpuSky{}, stack.voxelSize0);
  const gs::ObjectInstanceGpu& inst = frame_.instances[instance];
  const gs::ObjectMeshGpu& mesh = atlas_.meshes[inst.info.x];
  const std::uint32_t tableWords = std::uint32_t(cardTable_.size()) * 4u;
  p.cardTexels = cardTexels_.data();
  p.cardTableWords = tableWords;
  const std::uint32_t level =
      inst.info.w == gs::kNoCardLight ? 0u : inst.info.w >> gs::kCardLightLevelShift;
  for (std::uint32_t k = 0; k < gs::kCardsPerMesh; ++k) {
    const gs::CardGpu& c = cardTable_[inst.info.x * gs::kCardsPerMesh + k];
    const glm::uvec2 size = gs::cardLightSize(c, level);
    const std::uint32_t count = size.x * size.y;
    for (std::uint32_t t = 0; t < count; ++t) {
      const std::uint32_t cardTexel = p.cardLightTexel(c, level, t);
      const gs::CardTexelGpu& texel = cardTexels_[c.first.y - tableWords + c.first.x + cardTexel];
      out.push_back(
          gs::packRgb9e5(p.cardTexelRadiance(inst, mesh, c, cardTexel, texel, pc.counts.y,
                                             pc.params.x, pc.counts.w, pc.params.y, pc.counts.z)));
    }
  }
  return out;
}

}  // namespace sdfstream
