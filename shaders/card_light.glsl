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
