#version 450
// One primary ray per pixel centre, made on the GPU so a GPU-composed frame uploads nothing per
// pixel (shared/frame_layout.h, CameraRaysPush; the CPU's cameraRays in demo/gi_shading.cpp is
// the same math in double precision). Bindings: 0 rays (written). Threads spread over rows of
// 64 x 16384 as the shading pass's.
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/frame_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) writeonly buffer Rays { TraceRay rays[]; };

layout(push_constant) uniform Push { CameraRaysPush pc; };

void main() {
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
  uint width = pc.size.x;
  if (id >= width * pc.size.y) return;
  float u = 2.0 * (float(id % width) + 0.5) / float(width) - 1.0;
  float v = 1.0 - 2.0 * (float(id / width) + 0.5) / float(pc.size.y);
  vec3 d = normalize(pc.forward.xyz + u * pc.right.xyz + v * pc.up.xyz);
  vec3 o = pc.origin.xyz;
  float tMin = 0.0;
  float tMax = 1e30;
  if (pc.windowHi.w > 0.5) {
    // Rays start only inside a window: from outside, where the ray enters the outermost one,
    // a thousandth of a voxel in (inside the half-open window, still in its first cell).
    vec3 lo = pc.windowLo.xyz;
    vec3 hi = pc.windowHi.xyz;
    bool inside = all(greaterThanEqual(o, lo)) && all(lessThan(o, hi));
    if (!inside) {
      float tEnter = tMin;
      float tExit = tMax;
      for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
          if (o[a] < lo[a] || o[a] >= hi[a]) tEnter = tExit + 1.0;
          continue;
        }
        float t0 = (lo[a] - o[a]) / d[a];
        float t1 = (hi[a] - o[a]) / d[a];
        tEnter = max(tEnter, min(t0, t1));
        tExit = min(tExit, max(t0, t1));
      }
      tMin = tEnter <= tExit ? tEnter + 1e-3 : tMax * 2.0;
    }
  }
  TraceRay r;
  r.originTMin = vec4(o, tMin);
  r.dirTMax = vec4(d, tMax);
  rays[id] = r;
}
