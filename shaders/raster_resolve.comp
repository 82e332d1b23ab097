#version 450
// The raster primary's visibility buffer resolved on the device (raster/mesh_view_raster.h,
// MeshViewRaster::recordResolve): per pixel the point on its triangle, the geometric normal
// turned towards the eye, and the material's base colour and emission filtered over the pixel's
// footprint, in stack space: PrimarySurface, as resolvePrimarySurfaces (its CPU reference, in
// double precision, with world/triangle_scene.cpp's texture taps) computes it.
// Bindings: 0 visibility (width·height triangle ids, then width·height barycentric pairs),
// 1 positions (vec4), 2 indices (uint, three a triangle), 3 UVs (vec4: set 0 xy, set 1 zw),
// 4 material per triangle (uint), 5 materials, 6 textures, 7 levels, 8 texels (RGBA8 sRGB),
// 9 surfaces (written).
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/color_codec.h"
#include "shaders/shared/frame_layout.h"
#include "shaders/shared/shade_layout.h"
#include "shaders/shared/view_raster_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Visibility { uint visibility[]; };
layout(std430, binding = 1) readonly buffer Positions { vec4 positions[]; };
layout(std430, binding = 2) readonly buffer Indices { uint indices[]; };
layout(std430, binding = 3) readonly buffer Uvs { vec4 uvs[]; };
layout(std430, binding = 4) readonly buffer TriangleMaterial { uint triangleMaterial[]; };
layout(std430, binding = 5) readonly buffer Materials { RasterMaterialGpu materials[]; };
layout(std430, binding = 6) readonly buffer Textures { RasterTextureGpu textures[]; };
layout(std430, binding = 7) readonly buffer Levels { RasterLevelGpu levels[]; };
layout(std430, binding = 8) readonly buffer Texels { uint texels[]; };
layout(std430, binding = 9) writeonly buffer Surfaces { PrimarySurface surfaces[]; };

layout(push_constant) uniform Push { RasterResolvePush pc; };

// world/color_pack.h's packAlbedo: sRGB-encoded RGB, linear alpha, R in the low byte.
uint packSrgbAlbedo(vec4 c) {
  uint a = uint(floor(clamp(c.w, 0.0, 1.0) * 255.0 + 0.5));
  return frameSrgb8(c.x) | (frameSrgb8(c.y) << 8) | (frameSrgb8(c.z) << 16) | (a << 24);
}

int wrapRepeat(int i, int n) {
  int m = i % n;
  return m < 0 ? m + n : m;
}

vec4 texel(RasterLevelGpu level, int x, int y) {
  int w = int(level.info.y);
  int h = int(level.info.z);
  uint v = texels[level.info.x + uint(wrapRepeat(y, h) * w + wrapRepeat(x, w))];
  vec4 c = unpackAlbedo(v);
  return vec4(frameSrgbToLinear(c.x), frameSrgbToLinear(c.y), frameSrgbToLinear(c.z), c.w);
}

// Bilinear with REPEAT wrap, sRGB decoded before filtering; texel centres at (i + 0.5) / w.
vec4 sampleLevel(RasterLevelGpu level, vec2 uv) {
  uv -= floor(uv);
  float x = uv.x * float(level.info.y) - 0.5;
  float y = uv.y * float(level.info.z) - 0.5;
  float x0f = floor(x);
  float y0f = floor(y);
  float fx = x - x0f;
  float fy = y - y0f;
  int x0 = int(x0f);
  int y0 = int(y0f);
  vec4 top = mix(texel(level, x0, y0), texel(level, x0 + 1, y0), fx);
  vec4 bottom = mix(texel(level, x0, y0 + 1), texel(level, x0 + 1, y0 + 1), fx);
  return mix(top, bottom, fy);
}

// One material slot's tap (sampleSlot): white when the texture is unusable, the factor alone
// (returned as a flag: w < 0) when the slot has no texture or its UV set is missing.
vec4 sampleSlot(int textureIndex, int uvSet, vec4 transform, vec2 offset, uint tri, vec2 bary,
                float footprint) {
  if (textureIndex < 0 || uvSet < 0 || uvSet > 1) return vec4(-1.0);
  if ((pc.size.w & (1u << uint(uvSet))) == 0u) return vec4(-1.0);
  uint i0 = indices[3u * tri];
  uint i1 = indices[3u * tri + 1u];
  uint i2 = indices[3u * tri + 2u];
  vec2 t0 = uvSet == 0 ? uvs[i0].xy : uvs[i0].zw;
  vec2 t1 = uvSet == 0 ? uvs[i1].xy : uvs[i1].zw;
  vec2 t2 = uvSet == 0 ? uvs[i2].xy : uvs[i2].zw;
  vec2 uv = t0 * (1.0 - bary.x - bary.y) + t1 * bary.x + t2 * bary.y;
  vec2 at = transform.xy * uv.x + transform.zw * uv.y + offset;
  RasterTextureGpu tex = textures[textureIndex];
  if (tex.levels.y == 0u) return vec4(1.0);
  RasterLevelGpu base = levels[tex.levels.x];
  uint extra = tex.levels.y - 1u;  // mip levels below the texture itself
  if (!(footprint > 0.0) || extra == 0u) return sampleLevel(base, at);
  // Texels per metre on this triangle, as sampleSlot computes them.
  vec3 p0 = positions[i0].xyz;
  vec3 p1 = positions[i1].xyz;
  vec3 p2 = positions[i2].xyz;
  float worldArea = length(cross(p1 - p0, p2 - p0));
  vec2 e1 = t1 - t0;
  vec2 e2 = t2 - t0;
  float uvScale = abs(transform.x * transform.w - transform.y * transform.z);
  float uvArea = abs(e1.x * e2.y - e1.y * e2.x) * uvScale;
  if (!(worldArea > 0.0) || !(uvArea > 0.0)) return sampleLevel(base, at);
  float texelsAcross =
      sqrt(uvArea / worldArea * float(base.info.y) * float(base.info.z)) * footprint;
  float lod = clamp(log2(max(texelsAcross, 1.0)), 0.0, float(extra));
  uint lower = uint(floor(lod));
  float f = lod - float(lower);
  vec4 a = sampleLevel(levels[tex.levels.x + lower], at);
  if (f <= 0.0 || lower >= extra) return a;
  return mix(a, sampleLevel(levels[tex.levels.x + lower + 1u], at), f);
}

void main() {
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
  uint pixels = pc.size.x * pc.size.y;
  if (id >= pixels) return;
  PrimarySurface s;
  s.position = vec4(0.0);
  s.normalT = vec4(0.0);
  s.albedo = 0u;
  s.emission = 0u;
  s.pad0 = 0u;
  s.pad1 = 0u;
  uint triangleId = visibility[id];
  if (triangleId == 0u || triangleId > pc.size.z) {
    surfaces[id] = s;
    return;
  }
  uint tri = triangleId - 1u;
  vec2 bary = vec2(uintBitsToFloat(visibility[pixels + 2u * id]),
                   uintBitsToFloat(visibility[pixels + 2u * id + 1u]));
  vec3 v0 = positions[indices[3u * tri]].xyz;
  vec3 v1 = positions[indices[3u * tri + 1u]].xyz;
  vec3 v2 = positions[indices[3u * tri + 2u]].xyz;
  vec3 p = v0 * (1.0 - bary.x - bary.y) + v1 * bary.x + v2 * bary.y;
  vec3 toEye = pc.eye.xyz - p;
  float distance = length(toEye);
  vec3 n = cross(v1 - v0, v2 - v0);
  float area = length(n);
  n = area > 0.0 ? n / area : toEye / max(distance, 1e-30);
  if (dot(n, toEye) < 0.0) n = -n;
  float cosine = max(dot(n, toEye) / max(distance, 1e-12), 0.05);
  float footprint = distance * pc.eye.w / sqrt(cosine);

  RasterMaterialGpu m = materials[triangleMaterial[tri]];
  vec4 albedo = m.baseColorFactor;
  vec4 tap = sampleSlot(m.textures.x, m.textures.y, m.baseUv, m.uvOffsets.xy, tri, bary,
                        footprint);
  if (tap.w >= 0.0) albedo *= tap;
  vec3 emission = m.emissive.xyz;
  if (emission != vec3(0.0)) {
    vec4 e = sampleSlot(m.textures.z, m.textures.w, m.emissiveUv, m.uvOffsets.zw, tri, bary,
                        footprint);
    if (e.w >= 0.0) emission *= e.xyz;
  }
  s.position = vec4((p - pc.stackOrigin.xyz) * pc.stackOrigin.w, 1.0);
  s.normalT = vec4(n, distance * pc.stackOrigin.w);
  s.albedo = packSrgbAlbedo(albedo);
  s.emission = packRgb9e5(emission);
  surfaces[id] = s;
}
