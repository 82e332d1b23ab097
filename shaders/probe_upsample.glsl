// Sampling the probe field at reduced resolution: which pixel of each S×S block is sampled (S,
// the block size, is 2 at half resolution and 4 at quarter resolution), the order the sampling
// pass visits the blocks in, and the depth/normal-aware upsample that gives every other pixel
// its irradiance. Shared by probe_sample.comp (its reduced-resolution mode), probe_upsample.comp
// and their C++ reference (gi/probe_upsample.cpp), which includes this file inside a struct.
//
// The image is the caller's queries, one per pixel, row by row (ProbeQuery, probe_layout.h); a
// pixel without a surface has the normal (0, 0, 0) and gets irradiance 0. The low-resolution
// image has ceil(W / S) × ceil(H / S) pixels; its pixel (bx, by) is sampled at the first pixel of
// the block (S bx, S by) .. (S bx + S − 1, S by + S − 1) that has a surface, row by row, and
// stores vec4(irradiance, that pixel's index k = i + S j in the block), or w = -1 where no pixel
// of the block has a surface. So a sampled pixel keeps exactly its own irradiance, and every
// other pixel's own block always has a sample to fall back on.
//
// The includer defines PROBE_UPSAMPLE_QUERY(i) (the ProbeQuery of full-resolution pixel i) and,
// for probeUpsamplePixel, PROBE_UPSAMPLE_LOW(i) (the vec4 of low-resolution pixel i).

// A pixel has a surface where its query's normal is not zero.
bool probeQueryHasSurface(ProbeQuery q) { return dot(vec3(q.normal), vec3(q.normal)) > 0.0f; }

// The low-resolution pixel of invocation `id` when an image of `width` pixels per row is
// visited in 8×8 tiles, row by row, each tile in Z-order (the bits of x and y interleaved): so
// the sampling pass's groups of kProbeSampleShareLanes invocations are 4×2 blocks of
// neighbouring pixels, as its SDF-test sharing expects. Invocations past the image's edge map
// outside it (the caller checks x and y against the image).
uvec2 probeTiledPixel(uint id, uint width) {
  uint tilesPerRow = (width + 7u) / 8u;
  uint tile = id / 64u;
  uint z = id % 64u;
  uint x = (z & 1u) | ((z >> 1u) & 2u) | ((z >> 2u) & 4u);
  uint y = ((z >> 1u) & 1u) | ((z >> 2u) & 2u) | ((z >> 3u) & 4u);
  return uvec2((tile % tilesPerRow) * 8u + x, (tile / tilesPerRow) * 8u + y);
}

// Invocations the sampling pass needs for a low-resolution image: whole 8×8 tiles.
uint probeTiledInvocations(uint width, uint height) {
  return ((width + 7u) / 8u) * ((height + 7u) / 8u) * 64u;
}

// Index k = i + size j in its block of the pixel that low-resolution pixel (bx, by) samples,
// size² if none has a surface (pixels past the image's edge have none).
uint probeBlockSampledPixel(uvec2 block, uint size, uint width, uint height) {
  for (uint k = 0u; k < size * size; ++k) {
    uvec2 p = block * size + uvec2(k % size, k / size);
    if (p.x < width && p.y < height && probeQueryHasSurface(PROBE_UPSAMPLE_QUERY(p.x + width * p.y)))
      return k;
  }
  return size * size;
}

// The same at half resolution (2×2 blocks: 0-3, 4 if none).
uint probeHalfSampledPixel(uvec2 block, uint width, uint height) {
  return probeBlockSampledPixel(block, 2u, width, height);
}

// How much a sample taken at (pk, nk) may stand for a receiver at (p, n), in [0, 1]: both
// normals alike (cosine^8: 0.5 at 23.5°) and each point near the other's tangent plane, within
// half a cascade-0 voxel plus a quarter of their distance (neighbouring pixels of a surface
// seen at a grazing angle are far apart but coplanar; a step, a pole in front of a wall or a
// sill's edge is not).
float probeUpsampleSimilarity(vec3 p, vec3 n, vec3 pk, vec3 nk) {
  float c = max(dot(n, nk), 0.0f);
  c = c * c;
  c = c * c;
  c = c * c;
  vec3 d = pk - p;
  float plane = max(abs(dot(n, d)), abs(dot(nk, d)));
  float tolerance = 0.5f + 0.25f * length(d);
  float x = plane / tolerance;
  return c / (1.0f + 16.0f * x * x * x * x);
}

#ifdef PROBE_UPSAMPLE_LOW
// Irradiance at full-resolution pixel (x, y) of an image sampled in size × size blocks: its own
// sample where it was sampled; else the bilinear neighbours among the low-resolution samples
// (its own block and the next ones in x and y), each weighted by its similarity; where none is
// similar enough, the most similar one (its own block's at worst: never a pixel without a
// surface).
vec3 probeUpsampleBlockPixel(uint x, uint y, uint size, uint width, uint height) {
  ProbeQuery q = PROBE_UPSAMPLE_QUERY(x + width * y);
  if (!probeQueryHasSurface(q)) return vec3(0.0f);
  uint lowWidth = (width + size - 1u) / size;
  uint lowHeight = (height + size - 1u) / size;
  vec4 own = PROBE_UPSAMPLE_LOW(x / size + lowWidth * (y / size));
  uint ownPixel = uint(max(own.w, 0.0f));
  if (ownPixel % size == x % size && ownPixel / size == y % size) return vec3(own);
  vec3 p = vec3(q.position);
  vec3 n = vec3(q.normal);
  // A block's sample usually lies at its first pixel (S bx, S by), so the pixel's
  // low-resolution coordinates are (x / S, y / S): its own block, and (x mod S) / S of the way
  // to the next. Linear irradiance on a plane is then reproduced exactly.
  int x0 = int(x / size);
  int y0 = int(y / size);
  float fx = float(x % size) / float(size);
  float fy = float(y % size) / float(size);
  vec3 sum = vec3(0.0f);
  float weights = 0.0f;
  float best = -1.0f;
  vec3 bestValue = vec3(own);
  for (uint k = 0u; k < 4u; ++k) {
    int bx = clamp(x0 + int(k & 1u), 0, int(lowWidth) - 1);
    int by = clamp(y0 + int(k >> 1u), 0, int(lowHeight) - 1);
    vec4 neighbour = PROBE_UPSAMPLE_LOW(uint(bx) + lowWidth * uint(by));
    if (neighbour.w < 0.0f) continue;
    uint sampled = uint(neighbour.w);
    uint sx = uint(bx) * size + sampled % size;
    uint sy = uint(by) * size + sampled / size;
    ProbeQuery s = PROBE_UPSAMPLE_QUERY(sx + width * sy);
    float similarity = probeUpsampleSimilarity(p, n, vec3(s.position), vec3(s.normal));
    float bilinear = ((k & 1u) != 0u ? fx : 1.0f - fx) * ((k >> 1u) != 0u ? fy : 1.0f - fy);
    sum += vec3(neighbour) * (bilinear * similarity);
    weights += bilinear * similarity;
    if (similarity > best) {
      best = similarity;
      bestValue = vec3(neighbour);
    }
  }
  // 1e-3: at least one neighbour about as alike as a coplanar one at 0.1% of its bilinear share.
  return weights > 1e-3f ? sum / weights : bestValue;
}

// The same at half resolution (2×2 blocks).
vec3 probeUpsamplePixel(uint x, uint y, uint width, uint height) {
  return probeUpsampleBlockPixel(x, y, 2u, width, height);
}
#endif
