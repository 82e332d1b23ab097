// One tile of a world pack from the union of SdfSources: every LOD's bricks and empty-space data
// (partition.h), with the conservative LOD filter below. Pure CPU, no OpenVDB here.
//
// LOD rule (conservative min-filter, docs/DECISIONS.md "Coarse LODs"): LOD 0 is the union of the
// sources' LOD-0 samples. For l ≥ 1, with f the filtered field and s the sources' union at LOD l
// (both in LOD-l voxel units):
//     f_l(i) = min( s_l(i),  min over q in 2i + {0, ±x, ±y, ±z} of f_{l-1}(q) / 2 )
// where fine values saturated at +kNarrowBand take no part (they say only "at least the band",
// which s_l knows better). Fine samples inside a wall pull the coarse samples one fine voxel
// away negative, so a wall one LOD-0 voxel thick stays closed (the field is ≤ 0 somewhere along
// every line through it) at every LOD. The window reaches half a coarse voxel, so over the chain
// solids grow by at most (1 - 2^-l) LOD-l voxels: signs stay right beyond one LOD-l voxel from
// the surface (a 3³ window would reach √3/2 per level, ~1.5 voxels at LOD 3, and measurably
// flipped signs there). Distances are never raised, so sphere tracing stays safe. The chain starts
// at LOD 0 and each level is computed over the tile plus a margin wide enough for the next, so a
// tile needs no other tile. Materials: a coarse cell takes the material of the fine cell (of its
// 2³) with the smallest |d| at its nearest sample; cells whose fine cells have none sample the
// sources at LOD l. An inherited emitter's emission is scaled by its source's emissionRatio
// (the emitter's surface grows with the voxel; the factor keeps its flux).
//
// Bricks: a brick is stored iff any of its 9³ filtered samples has |d| < kNarrowBand.
// emptyDistance: Chebyshev brick distance over the tile plus the ring (kEmptyMargin bricks, or
// the wider margin the chain needed) where ring bricks are judged by the same rule; slots beyond
// count as occupied. Ring bricks' fine windows reach past the computed fine region, so their
// occupancy also relies on the sources' LOD contract (sdf_source.h: LOD l sees any LOD-0 surface
// within its band).
#pragma once

#include <vector>

#include "world/partition.h"
#include "world/sdf_source.h"

namespace sdfstream {

// Preconditions: spec.valid(); every source prepared (prepareLod) for LODs 0..lodCount-1.
// Sources whose bounds, grown by the band plus one brick, miss a brick are not asked for it.
// Single-threaded and deterministic; call concurrently for different tiles. Memory: the tile plus
// margin at one LOD as floats for bricks near a surface (≈ 3 KB per such brick).
Tile buildTile(const std::vector<const SdfSource*>& sources, const PartitionSpec& spec,
               glm::ivec3 tile);

}  // namespace sdfstream
