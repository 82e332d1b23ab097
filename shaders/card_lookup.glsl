// Reading a moving object's light from its cards (GS slides b, "Storing lighting information":
// a hit on an object takes its light from the card texels facing it; Lumen's surface cache reads
// its cards the same way). Shared by the probe trace, object_trace.comp and the CPU reference
// (gi/object_scene_cpu.cpp). The includer has included object_trace.glsl (OBJ_* macros,
// objAffine) and defines
//   OBJ_CARD(i)        -> CardGpu i (mesh m's cards are m * 6 .. m * 6 + 5)
//   OBJ_CARD_TEXEL(i)  -> CardTexelGpu i (CardGpu::first.y is a mesh's first)
//   OBJ_CARD_LIGHT(i)  -> uint RGB9E5 i (ObjectInstanceGpu::info.w is an instance's first)
// Same rules as sdf_trace.glsl (no swizzles, no out parameters, f-suffixed literals).

struct CardLookup {
  vec3 radiance;  // blended light of the accepted texels (emission + direct light)
  float weight;   // sum of the accepted cards' normal weights; 0: no card saw the point
  uint texel;     // the first accepted texel (mesh texel index), kNoCardLight when none
};

// The up to three cards facing the hit normal (weights n_a², which sum to 1), each accepting its
// texel under the hit when the depth it stored is within kCardDepthTolerance object-grid voxels
// of the hit's (the slides' rule: a card that sees another surface in front of the hit, or
// behind it, does not hold its light). Nearest texel, no filtering; the light comes from the light
// texel covering it at the instance's light level (card_layout.h).
CardLookup cardLookup(uint instance, vec3 pStack, vec3 nStack) {
  CardLookup r;
  r.radiance = vec3(0.0f);
  r.weight = 0.0f;
  r.texel = kNoCardLight;
  ObjectInstanceGpu inst = OBJ_INSTANCE(instance);
  uint lightBase = inst.info.w;
  if (lightBase == kNoCardLight) return r;
  uint level = lightBase >> kCardLightLevelShift;
  lightBase = lightBase & kCardLightBaseMask;
  ObjectMeshGpu m = OBJ_MESH(inst.info.x);
  vec3 g = objAffine(inst.gridFromStack[0], inst.gridFromStack[1], inst.gridFromStack[2], pStack);
  vec3 p = vec3(m.gridMin.x, m.gridMin.y, m.gridMin.z) + g * m.gridMin.w;
  // Normals map by the inverse transpose: grid normal ∝ stackFromGridᵀ · n.
  vec3 r0 = vec3(inst.stackFromGrid[0].x, inst.stackFromGrid[0].y, inst.stackFromGrid[0].z);
  vec3 r1 = vec3(inst.stackFromGrid[1].x, inst.stackFromGrid[1].y, inst.stackFromGrid[1].z);
  vec3 r2 = vec3(inst.stackFromGrid[2].x, inst.stackFromGrid[2].y, inst.stackFromGrid[2].z);
  vec3 n = r0 * nStack.x + r1 * nStack.y + r2 * nStack.z;
  float len = length(n);
  if (!(len > 0.0f)) return r;
  n = n / len;
  float tolerance = kCardDepthTolerance * m.gridMin.w;
  for (uint a = 0u; a < 3u; ++a) {
    float w = n[a] * n[a];
    if (w < 1e-4f) continue;
    CardGpu c = OBJ_CARD(inst.info.x * kCardsPerMesh + 2u * a + (n[a] > 0.0f ? 0u : 1u));
    if (c.info.z == 0u) continue;  // mesh without cards
    float fi = (p[(a + 1u) % 3u] - c.plane.x) / c.texel.x;
    float fj = (p[(a + 2u) % 3u] - c.plane.y) / c.texel.y;
    uint i = uint(clamp(int(floor(fi)), 0, int(c.info.z) - 1));
    uint j = uint(clamp(int(floor(fj)), 0, int(c.info.w) - 1));
    uint local = c.first.x + i + c.info.z * j;
    CardTexelGpu t = OBJ_CARD_TEXEL(c.first.y + local);
    if (t.depth < 0.0f || abs(t.depth - cardDepth(c, p)) > tolerance) continue;
    r.radiance += unpackRgb9e5(OBJ_CARD_LIGHT(lightBase + cardLightIndex(c, level, i, j))) * w;
    r.weight += w;
    if (r.texel == kNoCardLight) r.texel = local;
  }
  if (r.weight > 0.0f) r.radiance = r.radiance / r.weight;
  return r;
}
