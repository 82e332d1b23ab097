#version 450
// Card capture, vertex stage (cards/card_rasterizer.h, raster/visibility_raster.h): vertex
// pulling from storage buffers, three vertices per triangle of a non-indexed draw, so the
// triangle index and the corner's barycentric coordinates come from gl_VertexIndex alone (no
// vertex input state, and no gl_PrimitiveID in the fragment stage, which would need the
// geometry-shader feature).
#extension GL_GOOGLE_include_directive : require
#include "shaders/shared/card_layout.h"

layout(std430, set = 0, binding = 0) readonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };

layout(push_constant) uniform Push { CardCapturePush push; };

layout(location = 0) flat out uint outTriangle;
layout(location = 1) noperspective out vec2 outBary;

void main() {
  uint corner = uint(gl_VertexIndex) % 3u;
  vec4 p = vec4(positions[indices[gl_VertexIndex]].xyz, 1.0);
  gl_Position = vec4(dot(push.clipFromObject[0], p), dot(push.clipFromObject[1], p),
                     dot(push.clipFromObject[2], p), 1.0);
  outTriangle = uint(gl_VertexIndex) / 3u;
  outBary = vec2(corner == 1u ? 1.0 : 0.0, corner == 2u ? 1.0 : 0.0);
}
