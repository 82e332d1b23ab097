// Card atlases (GS slides b, "Storing lighting information"; Lumen's surface cache, Flax's global
// surface atlas): each object mesh gets six axis-aligned orthographic views of its object-space
// box, its *cards*, captured once per mesh. A card texel holds the surface the view sees first:
// albedo, emission, normal and depth. Shared by the capture (cards/), its CPU reference and the
// lookup; one definition, sizes static_asserted below.
//
// Card k of a mesh (k = 2 · axis + side, side 0 = the + face, 1 = the − face) lies on the plane
// of its face of the box (padded by CardGpu::originDepth's depth pad), looks into the box along
// −axis (side 0) or +axis (side 1), and spans the box's other two axes u = (axis + 1) % 3 and
// v = (axis + 2) % 3. Texel (i, j) has its centre at u = uMin + (i + 0.5)·texelU, v = vMin +
// (j + 0.5)·texelV, and lives at index firstTexel + i + width·j of the mesh's texels.
#ifndef SDFSTREAM_CARD_LAYOUT_H
#define SDFSTREAM_CARD_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"

SDF_BEGIN_NAMESPACE

#ifdef __cplusplus
using glm::normalize;
using glm::packSnorm2x16;
using glm::unpackSnorm2x16;
#endif

SDF_CONST uint kCardsPerMesh = 6;
// A card texel holds the light of a hit when its stored depth is within this many object-grid
// voxels of the hit's (GS slides b: texels of another surface in front or behind are rejected).
SDF_CONST float kCardDepthTolerance = 2.0f;

// One card of a mesh (object space).
struct CardGpu {
  vec4 plane;   // x: uMin, y: vMin, z: the plane's coordinate along the axis, w: depth extent
                // (object units from the plane through the box and its pads)
  vec4 texel;   // x: texelU, y: texelV (object units per texel); z, w: 0
  uvec4 info;   // x: axis (0..2), y: side (0: sees the + face, looks along −axis; 1: the
                // − face), z: width, w: height (texels)
  uvec4 first;  // x: first texel of this card in the mesh's texels (and of its light at
                // level 0); y: the mesh's first texel in the card buffer (set at upload);
                // z, w: first light texel of this card at light levels 1 and 2
};

// Card light levels (resolution by distance): an instance's light is kept at level l, one light
// texel per 2^l x 2^l card texels, so instances the finer cascades do not show (their probe rays
// resolve 2^c voxels) cost a quarter or a sixteenth of the texels and shadow rays. The card
// texels (capture) stay per mesh at full resolution; the lookup's depth test still uses them.
SDF_CONST uint kCardLightLevels = 3u;

// Light texels of card c at `level` along its u and v axes (x: width, y: height), rounded up.
#ifdef __cplusplus
inline
#endif
    uvec2
    cardLightSize(CardGpu c, uint level) {
  uint up = (1u << level) - 1u;
  return uvec2((c.info.z + up) >> level, (c.info.w + up) >> level);
}

#ifdef __cplusplus
inline
#endif
    uint
    cardLightFirst(CardGpu c, uint level) {
  return level == 0u ? c.first.x : (level == 1u ? c.first.z : c.first.w);
}

// Index (from the instance's light base) of the light texel covering card texel (i, j).
#ifdef __cplusplus
inline
#endif
    uint
    cardLightIndex(CardGpu c, uint level, uint i, uint j) {
  return cardLightFirst(c, level) + (i >> level) + cardLightSize(c, level).x * (j >> level);
}

// What a card texel sees (16 bytes). depth < 0: nothing (the view's ray leaves the box).
struct CardTexelGpu {
  uint albedo;    // RGBA8, sRGB-encoded RGB (shaders/shared/color_codec.h), as the bricks
  uint emission;  // RGB9E5, linear
  uint normal;    // object-space unit normal, octahedral, two snorm16 (x low), facing the card
  float depth;    // object units from the card's plane along its view direction
};

// Push constants of the capture's vertex shader: object position → clip space, as three rows
// applied to (p, 1) (orthographic: w = 1).
struct CardCapturePush {
  vec4 clipFromObject[3];
};

// Unit normal <-> CardTexelGpu::normal: octahedral map (Cigolle et al. 2014, "A Survey of
// Efficient Representations for Independent Unit Vectors"), two snorm16 with x in the low half.
#ifdef __cplusplus
inline
#endif
    uint
    cardPackNormal(vec3 n) {
  float l1 = (n.x < 0.0f ? -n.x : n.x) + (n.y < 0.0f ? -n.y : n.y) + (n.z < 0.0f ? -n.z : n.z);
  vec2 p = vec2(n.x, n.y) * (1.0f / (l1 > 0.0f ? l1 : 1.0f));
  if (n.z < 0.0f) {
    float px = (1.0f - (p.y < 0.0f ? -p.y : p.y)) * (p.x >= 0.0f ? 1.0f : -1.0f);
    float py = (1.0f - (p.x < 0.0f ? -p.x : p.x)) * (p.y >= 0.0f ? 1.0f : -1.0f);
    p = vec2(px, py);
  }
  return packSnorm2x16(p);
}

#ifdef __cplusplus
inline
#endif
    vec3
    cardUnpackNormal(uint v) {
  vec2 p = unpackSnorm2x16(v);
  float ax = p.x < 0.0f ? -p.x : p.x;
  float ay = p.y < 0.0f ? -p.y : p.y;
  vec3 n = vec3(p.x, p.y, 1.0f - ax - ay);
  if (n.z < 0.0f) {
    float nx = (1.0f - ay) * (p.x >= 0.0f ? 1.0f : -1.0f);
    float ny = (1.0f - ax) * (p.y >= 0.0f ? 1.0f : -1.0f);
    n = vec3(nx, ny, n.z);
  }
  return normalize(n);
}

SDF_END_NAMESPACE

#ifdef __cplusplus
static_assert(sizeof(sdfstream::gpu_shared::CardGpu) == 64);
static_assert(sizeof(sdfstream::gpu_shared::CardTexelGpu) == 16);
static_assert(sizeof(sdfstream::gpu_shared::CardCapturePush) == 48);
#endif

#endif
