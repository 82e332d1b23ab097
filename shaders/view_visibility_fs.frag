#version 450
// The camera's primary view of a mesh scene, fragment stage: the visibility buffer (triangle +
// 1, 0 = nothing, and the perspective-correct barycentrics of vertices 1 and 2), resolved into
// surfaces afterwards (raster/mesh_view_raster.h).
layout(location = 0) flat in uint inTriangle;
layout(location = 1) smooth in vec2 inBary;

layout(location = 0) out uint outId;
layout(location = 1) out vec2 outBary;

void main() {
  outId = inTriangle + 1u;
  outBary = inBary;
}
