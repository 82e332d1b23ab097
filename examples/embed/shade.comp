#version 450
// The example engine's own shading pass: irradiance(x, n, view) of sdfstream's probes on a grid
// of points of a horizontal plane (normal up, seen from above), read straight from the probe
// buffers through the installed GLSL include. sdfstream's eight buffers sit at set 0, bindings
// 0-7 (the defaults); the engine's output follows at binding 8.
#extension GL_GOOGLE_include_directive : require
#include "sdfstream/probe_sample.glsl"

layout(std430, set = 0, binding = 8) writeonly buffer Pixels { vec4 pixels[]; };
layout(push_constant) uniform Push {
  vec4 originStep;  // xyz: the grid's first point in probe-field coordinates; w: spacing
  uvec4 size;       // x, y: image size
} pc;
layout(local_size_x = 64) in;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.size.x * pc.size.y) return;
  vec3 p = pc.originStep.xyz + vec3(float(i % pc.size.x), 0.0, float(i / pc.size.x)) * pc.originStep.w;
  pixels[i] = vec4(sdfstreamIrradiance(p, vec3(0.0, 1.0, 0.0), vec3(0.0, 1.0, 0.0)), 1.0);
}
