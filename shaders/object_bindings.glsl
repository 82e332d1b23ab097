// The eight buffers every object pass reads (gi/object_scene.h owns them), bound from `base` on:
// meta (frame constants + mesh table), instances, regions, region lists, object-SDF distances,
// object materials, the card atlas (every mesh's six CardGpu as four uvec4 each, then the card
// texels, one uvec4 each: cards/ and shaders/shared/card_layout.h) and the instances' card light
// (RGB9E5 per card texel, written by card_light.comp). The includer defines OBJ_BINDING_BASE
// first; object_trace.glsl (and card_lookup.glsl) follow.
#include "shaders/shared/object_layout.h"
#include "shaders/shared/card_layout.h"

layout(std430, binding = OBJ_BINDING_BASE + 0) readonly buffer ObjectMeta {
  ObjectFrameGpu objFrame;
  ObjectMeshGpu objMeshes[];
};
layout(std430, binding = OBJ_BINDING_BASE + 1) readonly buffer ObjectInstances {
  ObjectInstanceGpu objInstances[];
};
layout(std430, binding = OBJ_BINDING_BASE + 2) buffer ObjectRegions { ObjectRegionGpu objRegions[]; };
layout(std430, binding = OBJ_BINDING_BASE + 3) buffer ObjectLists { uvec4 objList[]; };
layout(std430, binding = OBJ_BINDING_BASE + 4) readonly buffer ObjectDistance { float objDist[]; };
layout(std430, binding = OBJ_BINDING_BASE + 5) readonly buffer ObjectMaterial { uvec2 objMat[]; };
layout(std430, binding = OBJ_BINDING_BASE + 6) readonly buffer ObjectCards { uvec4 objCardData[]; };
layout(std430, binding = OBJ_BINDING_BASE + 7) readonly buffer ObjectCardLight { uint objCardLight[]; };

CardGpu objCard(uint i) {
  CardGpu c;
  c.plane = uintBitsToFloat(objCardData[4u * i]);
  c.texel = uintBitsToFloat(objCardData[4u * i + 1u]);
  c.info = objCardData[4u * i + 2u];
  c.first = objCardData[4u * i + 3u];
  return c;
}

CardTexelGpu objCardTexel(uint i) {
  uvec4 d = objCardData[i];
  CardTexelGpu t;
  t.albedo = d.x;
  t.emission = d.y;
  t.normal = d.z;
  t.depth = uintBitsToFloat(d.w);
  return t;
}

#define OBJ_FRAME objFrame
#define OBJ_MESH(m) objMeshes[m]
#define OBJ_INSTANCE(i) objInstances[i]
#define OBJ_REGION(i) objRegions[i]
#define OBJ_LIST(i) objList[i]
#define OBJ_DIST(i) objDist[i]
#define OBJ_MAT(i) objMat[i]
#define OBJ_CARD(i) objCard(i)
#define OBJ_CARD_TEXEL(i) objCardTexel(i)
#define OBJ_CARD_LIGHT(i) objCardLight[i]
