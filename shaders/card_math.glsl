// Card geometry shared by the card light pass, the lookup and their C++ references (one
// definition, as sdf_trace.glsl: no swizzles, no out parameters, f-suffixed literals). The
// conventions are shaders/shared/card_layout.h's; cards/card_layout.cpp builds the cards.

// Unit view direction of a card (into the box).
vec3 cardViewDir(CardGpu c) {
  vec3 d = vec3(0.0f);
  d[c.info.x] = c.info.y == 0u ? -1.0f : 1.0f;
  return d;
}

// Object-space point seen by texel (i, j) of card c at `depth` from its plane.
vec3 cardTexelPoint(CardGpu c, uint i, uint j, float depth) {
  uint a = c.info.x;
  vec3 p = vec3(0.0f);
  p[(a + 1u) % 3u] = c.plane.x + (float(i) + 0.5f) * c.texel.x;
  p[(a + 2u) % 3u] = c.plane.y + (float(j) + 0.5f) * c.texel.y;
  p[a] = c.plane.z;
  return p + cardViewDir(c) * depth;
}

// Depth of object point p along card c's view (object units from its plane).
float cardDepth(CardGpu c, vec3 p) {
  float along = p[c.info.x];
  return c.info.y == 0u ? c.plane.z - along : along - c.plane.z;
}
