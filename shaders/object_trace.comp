#version 450
// Traces rays against the moving objects only (gi/object_scene.h, ObjectScene::trace): through
// the macro-region lists (mode 0) or against every instance (mode 1, the brute-force peer of the
// tests and the stress benchmark's naive mode). Bindings 0-5: object buffers
// (object_bindings.glsl); 6 rays (TraceRay, stack space); 7 hits (ObjectTraceHit).
#extension GL_GOOGLE_include_directive : require

#define SDF_PRECISE precise
#define OBJ_BINDING_BASE 0
#include "shaders/object_bindings.glsl"
#include "shaders/shared/sdf_layout.h"

layout(std430, binding = 6) readonly buffer Rays { TraceRay rays[]; };
layout(std430, binding = 7) writeonly buffer Hits { ObjectTraceHit hits[]; };

layout(push_constant) uniform Push { ObjectTracePush pc; };

#include "shaders/object_trace.glsl"

layout(local_size_x = 64) in;

void main() {
  uint id = gl_GlobalInvocationID.x;
  if (id >= pc.rayCount) return;
  TraceRay ray = rays[id];
  vec3 o = vec3(ray.originTMin.x, ray.originTMin.y, ray.originTMin.z);
  vec3 d = vec3(ray.dirTMax.x, ray.dirTMax.y, ray.dirTMax.z);
  ObjectHit h = pc.mode == 0u ? objTraceRegions(o, d, ray.originTMin.w, ray.dirTMax.w, 0u)
                              : objTraceAll(o, d, ray.originTMin.w, ray.dirTMax.w);
  ObjectTraceHit out_;
  out_.normalT = vec4(h.normal, h.t);
  out_.instance = h.instance;
  out_.albedo = h.albedo;
  out_.emission = h.emission;
  out_.steps = h.steps;
  out_.tried = h.instancesTried;
  out_.pad0 = 0u;
  out_.pad1 = 0u;
  out_.pad2 = 0u;
  hits[id] = out_;
}
