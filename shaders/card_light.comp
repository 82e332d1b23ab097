#version 450
// Card light pass (gi/object_scene.h, ObjectScene card light; math in card_light.glsl): a row
// of workgroups per listed instance (y = index into the relight list; x: enough workgroups for
// the largest card), its threads over the texels of each of the instance's mesh's six cards;
// each light texel (one per 2^level x 2^level card texels at the instance's light level,
// card_layout.h) is written as RGB9E5 at the instance's card-light base (ObjectInstanceGpu::info.w)
// + its index at that level, lit at the card texel cardLightTexel picks. Instances not listed keep
// the light they had (relit within a per-frame budget, moved ones first: gi/card_light_slots.h).
// Bindings: 0 relight list (instance indices), 1 lights, 2 card light (written; the same buffer
// as object binding 15), 3 page tables, 4 distance atlas (or,
// where specialization constant 0 says so, the corner atlas: the same distances by cell), 5 albedo
// atlas, 6 emission atlas,
// 7 cascade params (as light_cache.comp), 8-15 moving objects (object_bindings.glsl), 16 the count
// of texels whose light came out NaN or infinite (packing would hide them as black or white).
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/light_layout.h"
#include "shaders/shared/color_codec.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer RelightList { uint relightList[]; };
layout(std430, binding = 1) readonly buffer Lights { GpuLight lights[]; };
layout(std430, binding = 2) writeonly buffer CardLightOut { uint cardLightOut[]; };
layout(std430, binding = 3) readonly buffer PageTable { uint pageTable[]; };
layout(std430, binding = 4) readonly buffer DistanceAtlas { uint distanceAtlas[]; };
layout(std430, binding = 4) readonly buffer CornerAtlas { uvec4 cornerAtlas[]; };
layout(std430, binding = 5) readonly buffer AlbedoAtlas { uint albedoAtlas[]; };
layout(std430, binding = 6) readonly buffer EmissionAtlas { uint emissionAtlas[]; };
layout(std430, binding = 7) readonly buffer Cascades { CascadeTraceParams cascades[]; };
layout(std430, binding = 16) buffer CardNonFinite { uint cardNonFinite; };

layout(push_constant) uniform Push { LightCachePushConstants pc; };

#define SDF_PAGE(i) pageTable[i]
#define SDF_DIST_WORD(i) distanceAtlas[i]
#define SDF_CELL_CORNERS(i) cornerAtlas[i]
#define SDF_ALBEDO(i) albedoAtlas[i]
#define SDF_EMISSION(i) emissionAtlas[i]
#define SDF_CASCADE(c) cascades[c]
#define LIGHT_AT(i) lights[i]
#define OBJ_BINDING_BASE 8
#include "shaders/object_bindings.glsl"
#include "shaders/sdf_trace.glsl"
#include "shaders/object_trace.glsl"
#include "shaders/light_math.glsl"
#include "shaders/card_math.glsl"
#include "shaders/card_light.glsl"

void main() {
  uint item = gl_WorkGroupID.y;
  if (item >= pc.counts.x) return;
  uint instance = relightList[item];
  ObjectInstanceGpu inst = OBJ_INSTANCE(instance);
  uint base = inst.info.w;
  if (base == kNoCardLight) return;
  uint level = base >> kCardLightLevelShift;
  base = base & kCardLightBaseMask;
  ObjectMeshGpu m = OBJ_MESH(inst.info.x);
  for (uint k = 0u; k < kCardsPerMesh; ++k) {
    CardGpu c = OBJ_CARD(inst.info.x * kCardsPerMesh + k);
    uvec2 size = cardLightSize(c, level);
    uint count = size.x * size.y;
    uint first = base + cardLightFirst(c, level);
    for (uint t = gl_GlobalInvocationID.x; t < count; t += gl_NumWorkGroups.x * gl_WorkGroupSize.x) {
      uint cardTexel = cardLightTexel(c, level, t);
      CardTexelGpu texel = OBJ_CARD_TEXEL(c.first.y + c.first.x + cardTexel);
      vec3 radiance = cardTexelRadiance(inst, m, c, cardTexel, texel, pc.counts.y, pc.params.x,
                                        pc.counts.w, pc.params.y, pc.counts.z);
      if (any(isnan(radiance)) || any(isinf(radiance))) atomicAdd(cardNonFinite, 1u);
      cardLightOut[first + t] = packRgb9e5(radiance);
    }
  }
}
