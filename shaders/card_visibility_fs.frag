#version 450
// Card capture, fragment stage: a visibility buffer (triangle + 1, 0 = empty, and the
// barycentric coordinates of vertices 1 and 2); materials are resolved from these afterwards by
// the same function the CPU reference uses (cards/card_texels.h).
layout(location = 0) flat in uint inTriangle;
layout(location = 1) noperspective in vec2 inBary;

layout(location = 0) out uint outId;
layout(location = 1) out vec2 outBary;

void main() {
  outId = inTriangle + 1u;
  outBary = inBary;
}
