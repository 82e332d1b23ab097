#version 450
// Regroups bricks of the distance atlas into cell corners (sdf_layout.h, kBrickCornerWords): one
// thread per cell of each listed slot. Bits are moved, never converted, so the corners hold the
// distance atlas's fp16 values exactly (denormals and signed zeros included).
// Bindings: 0 slots to regroup (uint each; unused when pc.listed == 0: slots 0..count-1),
// 1 distance atlas, 2 corner atlas.
#extension GL_GOOGLE_include_directive : require

#include "shaders/shared/sdf_layout.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Slots { uint slots[]; };
layout(std430, binding = 1) readonly buffer DistanceAtlas { uint distanceAtlas[]; };
layout(std430, binding = 2) writeonly buffer CornerAtlas { uvec4 cornerAtlas[]; };

layout(push_constant) uniform Push { BrickCornersPush pc; };

// The fp16 bits of sample (x, y, z) of a brick (9³ samples, two per word, x fastest).
uint sampleBits(uint base, uint x, uint y, uint z) {
  uint i = x + 9u * (y + 9u * z);
  return (distanceAtlas[base + (i >> 1u)] >> ((i & 1u) * 16u)) & 0xffffu;
}

uint pairBits(uint base, uint x, uint y, uint z) {
  return sampleBits(base, x, y, z) | (sampleBits(base, x + 1u, y, z) << 16u);
}

void main() {
  // spreadOverRows: 64-wide rows of groups.
  uint id = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
  uint k = id / kBrickMaterialCount;
  if (k >= pc.slotCount) return;
  uint slot = pc.listed != 0u ? slots[k] : k;
  uint cell = id % kBrickMaterialCount;
  uint x = cell & 7u, y = (cell >> 3u) & 7u, z = cell >> 6u;
  uint base = slot * kBrickDistanceWords;
  cornerAtlas[slot * kBrickMaterialCount + cell] =
      uvec4(pairBits(base, x, y, z), pairBits(base, x, y + 1u, z), pairBits(base, x, y, z + 1u),
            pairBits(base, x, y + 1u, z + 1u));
}
