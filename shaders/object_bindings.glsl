// The six buffers every object pass reads (gi/object_scene.h owns them), bound from `base` on:
// meta (frame constants + mesh table), instances, regions, region lists, object-SDF distances,
// object materials. The includer defines OBJ_BINDING_BASE first; object_trace.glsl follows.
#include "shaders/shared/object_layout.h"

layout(std430, binding = OBJ_BINDING_BASE + 0) readonly buffer ObjectMeta {
  ObjectFrameGpu objFrame;
  ObjectMeshGpu objMeshes[];
};
layout(std430, binding = OBJ_BINDING_BASE + 1) readonly buffer ObjectInstances {
  ObjectInstanceGpu objInstances[];
};
layout(std430, binding = OBJ_BINDING_BASE + 2) buffer ObjectRegions { ObjectRegionGpu objRegions[]; };
layout(std430, binding = OBJ_BINDING_BASE + 3) buffer ObjectLists { uint objList[]; };
layout(std430, binding = OBJ_BINDING_BASE + 4) readonly buffer ObjectDistance { float objDist[]; };
layout(std430, binding = OBJ_BINDING_BASE + 5) readonly buffer ObjectMaterial { uvec2 objMat[]; };

#define OBJ_FRAME objFrame
#define OBJ_MESH(m) objMeshes[m]
#define OBJ_INSTANCE(i) objInstances[i]
#define OBJ_REGION(i) objRegions[i]
#define OBJ_LIST(i) objList[i]
#define OBJ_DIST(i) objDist[i]
#define OBJ_MAT(i) objMat[i]
