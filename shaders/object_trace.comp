#version 450
// Traces rays against the moving objects only (gi/object_scene.h, ObjectScene::trace): through
// the macro-region lists (mode 0) or against every instance (mode 1, the brute-force peer of the
// tests and the stress benchmark's naive mode), and reads each hit's light from its instance's
// cards (card_lookup.glsl). Bindings 0-7: object buffers (object_bindings.glsl); 8 rays
// (TraceRay, stack space); 9 hits (ObjectTraceHit).
#extension GL_GOOGLE_include_directive : require

#define SDF_PRECISE precise
#define OBJ_BINDING_BASE 0
#include "shaders/object_bindings.glsl"
#include "shaders/shared/sdf_layout.h"

layout(std430, binding = 8) readonly buffer Rays { TraceRay rays[]; };
layout(std430, binding = 9) writeonly buffer Hits { ObjectTraceHit hits[]; };

layout(push_constant) uniform Push { ObjectTracePush pc; };

#include "shaders/shared/color_codec.h"
#include "shaders/object_trace.glsl"
#include "shaders/card_math.glsl"
#include "shaders/card_lookup.glsl"

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
  out_.cardLight = 0u;
  out_.cardWeight = floatBitsToUint(0.0);
  out_.cardTexel = kNoCardLight;
  if (h.t >= 0.0) {
    CardLookup card = cardLookup(h.instance, o + d * h.t, h.normal);
    out_.cardLight = packRgb9e5(card.radiance);
    out_.cardWeight = floatBitsToUint(card.weight);
    out_.cardTexel = card.texel;
  }
  hits[id] = out_;
}
