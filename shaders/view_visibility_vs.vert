#version 450
// The camera's primary view of a mesh scene, vertex stage (raster/mesh_view_raster.h): vertex
// pulling as the card capture's (card_visibility_vs.vert: three vertices per triangle of a
// non-indexed draw, the triangle and the corner's barycentrics from gl_VertexIndex), with a
// perspective projection (shared/view_raster_layout.h).
#extension GL_GOOGLE_include_directive : require
#include "shaders/shared/view_raster_layout.h"

layout(std430, set = 0, binding = 0) readonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer Indices { uint indices[]; };

layout(push_constant) uniform Push { ViewRasterPush push; };

layout(location = 0) flat out uint outTriangle;
layout(location = 1) smooth out vec2 outBary;  // perspective-correct

void main() {
  uint corner = uint(gl_VertexIndex) % 3u;
  vec4 p = vec4(positions[indices[gl_VertexIndex]].xyz, 1.0);
  gl_Position = vec4(dot(push.clipFromWorld[0], p), dot(push.clipFromWorld[1], p),
                     dot(push.clipFromWorld[2], p), dot(push.clipFromWorld[3], p));
  outTriangle = uint(gl_VertexIndex) / 3u;
  outBary = vec2(corner == 1u ? 1.0 : 0.0, corner == 2u ? 1.0 : 0.0);
}
