// The light of one card texel of a moving object's instance (GS slides b, "Storing lighting
// information": the cards hold the object's direct light, so its hits bounce what it receives):
// emission + albedo/π · Σ lights' irradiance at the surface point the texel saw, shadowed through
// the static cascades and the other objects (light_math.glsl). Indirect light is added where the
// light is read (the probe trace adds albedo · E(probes) / π, as for static hits), so objects take
// part in multi-bounce without a second copy of the probes' light here. The includer has included
// light_math.glsl, object_trace.glsl and card_math.glsl with their macros. Same rules as
// sdf_trace.glsl (no swizzles, no out parameters, f-suffixed literals).
vec3 cardTexelRadiance(ObjectInstanceGpu inst, ObjectMeshGpu m, CardGpu c, uint texel,
                       CardTexelGpu t, uint lightCount, float voxelSize0, uint maxSteps,
                       float hitEpsilon, uint cascadeCount) {
  vec3 emission = unpackRgb9e5(t.emission);
  if (t.depth < 0.0f || lightCount == 0u) return emission;
  uint i = texel % c.info.z;
  uint j = texel / c.info.z;
  vec3 pObject = cardTexelPoint(c, i, j, t.depth);
  vec3 g = (pObject - vec3(m.gridMin.x, m.gridMin.y, m.gridMin.z)) / m.gridMin.w;
  SDF_PRECISE vec3 p0 =
      objAffine(inst.stackFromGrid[0], inst.stackFromGrid[1], inst.stackFromGrid[2], g);
  // Normals map by the inverse transpose: stack normal ∝ gridFromStackᵀ · n.
  vec3 nObject = cardUnpackNormal(t.normal);
  vec3 r0 = vec3(inst.gridFromStack[0].x, inst.gridFromStack[0].y, inst.gridFromStack[0].z);
  vec3 r1 = vec3(inst.gridFromStack[1].x, inst.gridFromStack[1].y, inst.gridFromStack[1].z);
  vec3 r2 = vec3(inst.gridFromStack[2].x, inst.gridFromStack[2].y, inst.gridFromStack[2].z);
  vec3 n = normalize(r0 * nObject.x + r1 * nObject.y + r2 * nObject.z);
  // Two object-grid voxels along the normal, in stack voxels: clear of the object's own SDF.
  float offset =
      2.0f * length(objLinear(inst.stackFromGrid[0], inst.stackFromGrid[1], inst.stackFromGrid[2],
                              nObject));
  vec3 irradiance = vec3(0.0f);
  for (uint l = 0u; l < lightCount; ++l)
    irradiance += lightIrradianceOffset(LIGHT_AT(l), p0, n, offset, voxelSize0, maxSteps,
                                        hitEpsilon, cascadeCount);
  vec3 albedo = lightSrgbToLinear(vec3(unpackAlbedo(t.albedo)));
  return emission + albedo * irradiance * kLightInvPi;
}

// The card texel (index within card c) whose light stands for light texel t of c at `level`: of
// the 2^level x 2^level card texels it covers, the one that saw a surface (depth >= 0) nearest
// the footprint's centre (first in row order among equals), else the footprint's first texel.
// Needs OBJ_CARD_TEXEL (CardGpu::first.y is the mesh's first texel there).
uint cardLightTexel(CardGpu c, uint level, uint t) {
  uint lightWidth = cardLightSize(c, level).x;
  uint i0 = (t % lightWidth) << level;
  uint j0 = (t / lightWidth) << level;
  uint best = i0 + c.info.z * j0;
  if (level == 0u) return best;
  uint side = 1u << level;
  float centre = 0.5f * float(side) - 0.5f;
  float bestDistance = 1e30f;
  for (uint dj = 0u; dj < side; ++dj) {
    for (uint di = 0u; di < side; ++di) {
      uint i = i0 + di;
      uint j = j0 + dj;
      if (i >= c.info.z || j >= c.info.w) continue;
      uint texel = i + c.info.z * j;
      if (OBJ_CARD_TEXEL(c.first.y + c.first.x + texel).depth < 0.0f) continue;
      float du = float(di) - centre;
      float dv = float(dj) - centre;
      float d = du * du + dv * dv;
      if (d < bestDistance) {
        bestDistance = d;
        best = texel;
      }
    }
  }
  return best;
}
