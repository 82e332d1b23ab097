// The probe (DDGI) math: ray directions, octahedral texel mapping, border copy, blend weights,
// perceptual encoding, and the per-probe sampling weights. Single definition: GLSL passes
// include it after shaders/shared/probe_layout.h; gi/probe_math.cpp includes it as C++ inside a
// struct (the CPU reference, STYLE.md habit 9), the way gi/cpu_tracer.cpp includes sdf_trace.glsl.
//
// Rules that keep it valid in both languages: no swizzles, no out/inout parameters (return
// values/structs), float literals with an f suffix, no file-scope constants (they live in
// probe_layout.h), only functions both GLSL and glm provide. Includers provide nothing else.
//
// Seeds: Majercik et al. 2021, "Scaling Probe-Based Real-Time Dynamic Global Illumination for
// Production" (cited "M21 Sec. x"); Hvezda 2022, DDGI thesis (cited "H22 Sec. x").

// ---- Ray directions -------------------------------------------------------------------------

// Spherical Fibonacci point i of n (H22 Sec. 4.2, Eqs. 4.2-4.3, after Keinert 2015):
// phi_i = 2 pi i / Phi (Phi the golden ratio), z_i = 1 - (2i + 1) / n. Unit length, z-up.
vec3 probeSphericalFibonacci(uint i, uint n) {
  float fi = float(i);
  float goldenFraction = 0.6180339887498949f;  // 1 / Phi = Phi - 1
  float t = fi * goldenFraction;
  float phi = 6.283185307179586f * (t - floor(t));
  float cosTheta = 1.0f - (2.0f * fi + 1.0f) / float(n);
  float sinTheta = sqrt(clamp(1.0f - cosTheta * cosTheta, 0.0f, 1.0f));
  return vec3(cos(phi) * sinTheta, sin(phi) * sinTheta, cosTheta);
}

// Ray i of n of a probe this frame: the Fibonacci pattern turned by the frame's random rotation
// (M21 Sec. 2.3: "rotating the pattern randomly every frame"), so texels see new directions each
// frame and the temporal blend integrates the whole sphere.
vec3 probeRayDirection(uint i, uint n, mat3 rotation) {
  return rotation * probeSphericalFibonacci(i, n);
}

// ---- Octahedral mapping (Cigolle et al. 2014; M21 Sec. 3) ------------------------------------

vec2 probeSignNotZero(vec2 v) {
  return vec2(v.x >= 0.0f ? 1.0f : -1.0f, v.y >= 0.0f ? 1.0f : -1.0f);
}

// Unit direction -> octahedral coordinate in [-1,1]². The upper hemisphere (z >= 0) maps to the
// inner diamond |u|+|v| <= 1, the lower one is folded out to the corners.
vec2 probeOctEncode(vec3 d) {
  float l1 = abs(d.x) + abs(d.y) + abs(d.z);
  vec2 p = vec2(d.x, d.y) * (1.0f / l1);
  if (d.z < 0.0f) {
    p = (vec2(1.0f) - abs(vec2(p.y, p.x))) * probeSignNotZero(p);
  }
  return p;
}

// Octahedral coordinate in [-1,1]² -> unit direction (inverse of probeOctEncode).
vec3 probeOctDecode(vec2 p) {
  vec3 d = vec3(p.x, p.y, 1.0f - abs(p.x) - abs(p.y));
  if (d.z < 0.0f) {
    vec2 q = (vec2(1.0f) - abs(vec2(p.y, p.x))) * probeSignNotZero(p);
    d = vec3(q.x, q.y, d.z);
  }
  return normalize(d);
}

// Centre of interior texel `texel` (0..interior-1 per axis) in octahedral coordinates.
vec2 probeTexelCentreOct(uvec2 texel, uint interior) {
  return (vec2(texel) + vec2(0.5f)) * (2.0f / float(interior)) - vec2(1.0f);
}

// The direction a probe texel stands for (the centre of interior texel `texel`).
vec3 probeTexelDirection(uvec2 texel, uint interior) {
  return probeOctDecode(probeTexelCentreOct(texel, interior));
}

// Where direction d falls in a probe tile, in texels from the tile's corner (texel (x,y) covers
// [x, x+1) x [y, y+1)); the border shifts the interior by kProbeBorderTexels. For filtering,
// bilinear weights come from this minus 0.5 (texel centres sit at +0.5).
vec2 probeTileCoord(vec3 d, uint interior) {
  return (probeOctEncode(d) * 0.5f + vec2(0.5f)) * float(interior) +
         vec2(float(kProbeBorderTexels));
}

// Border copy rule for a 1-texel border (M21 Fig. 12a; H22 Fig. 4.9, after Engelhardt and
// Dachsbacher 2008). `tile` = interior + 2 texels per edge; returns the tile texel whose value
// tile texel t holds (t itself when interior). On the octahedral square the edge point (u, -1)
// is the same direction as (-u, -1) (and likewise for every edge), so a border texel copies the
// interior texel next to it mirrored along that edge; each corner copies the diagonally opposite
// interior corner, since all four corners are the direction (0, 0, -1).
uvec2 probeBorderSource(uvec2 t, uint tile) {
  uint last = tile - 1u;
  bool left = t.x == 0u;
  bool right = t.x == last;
  bool top = t.y == 0u;
  bool bottom = t.y == last;
  if ((left || right) && (top || bottom)) {
    return uvec2(left ? last - 1u : 1u, top ? last - 1u : 1u);
  }
  if (top || bottom) {
    return uvec2(last - t.x, top ? 1u : last - 1u);
  }
  if (left || right) {
    return uvec2(left ? 1u : last - 1u, last - t.y);
  }
  return t;
}

// Candidate k (0..7) of the border texels that may copy tile texel t: its mirrors on the four
// edges, then the four corners. It copies t iff probeBorderSource(candidate, tile) == t (an
// interior edge texel has one such copy, an interior corner three), so a pass that writes t can
// write its copies too.
uvec2 probeBorderCopyCandidate(uvec2 t, uint tile, uint k) {
  uint last = tile - 1u;
  if (k == 0u) return uvec2(last - t.x, 0u);
  if (k == 1u) return uvec2(last - t.x, last);
  if (k == 2u) return uvec2(0u, last - t.y);
  if (k == 3u) return uvec2(last, last - t.y);
  return uvec2((k & 1u) == 0u ? 0u : last, k < 6u ? 0u : last);
}

// ---- Blending (M21 Sec. 2.3 Eq. 1 and Sec. 4.2; H22 Sec. 4.5 Eqs. 4.12-4.16) ------------------

// Irradiance: cosine weight of a ray for a texel direction.
float probeIrradianceWeight(vec3 texelDir, vec3 rayDir) {
  return max(0.0f, dot(texelDir, rayDir));
}

// Depth moments: power-cosine weight (H22 Eq. 4.14, k_s up to 50; sharpness = 50 by default).
float probeDepthWeight(vec3 texelDir, vec3 rayDir, float sharpness) {
  return pow(max(0.0f, dot(texelDir, rayDir)), sharpness);
}

// Irradiance from one frame's sums (rgb = sum of w * radiance, a = sum of w with the cosine
// weights above). The normalised sum is the cosine-weighted mean radiance, which for directions
// uniform on the sphere estimates  E(n) / pi  where  E(n) = integral over the hemisphere around n
// of L(w) max(0, n.w) dw  (since the integral of max(0, n.w) is pi). So E = pi * rgb / a.
vec3 probeIrradianceFromSums(vec4 sums) {
  return sums.w > 0.0f ? vec3(sums) * (3.14159265358979f / sums.w) : vec3(0.0f);
}

// Hysteresis blend (M21 Eq. 1): new texel = h * old + (1 - h) * fresh.
vec3 probeHysteresisBlend3(vec3 oldValue, vec3 fresh, float hysteresis) {
  return mix(fresh, oldValue, hysteresis);
}
vec2 probeHysteresisBlend2(vec2 oldValue, vec2 fresh, float hysteresis) {
  return mix(fresh, oldValue, hysteresis);
}

// Perceptual encoding (M21 Sec. 4.2, Fig. 3): texels store irradiance^(1/gamma), gamma = 5, and
// are blended in that space, which makes light-to-dark transitions converge faster.
vec3 probeEncodeIrradiance(vec3 irradiance, float gamma) {
  return pow(max(irradiance, vec3(0.0f)), vec3(1.0f / gamma));
}
vec3 probeDecodeIrradiance(vec3 stored, float gamma) {
  return pow(max(stored, vec3(0.0f)), vec3(gamma));
}

// Per-texel change heuristic (M21 Sec. 4.3, Fig. 4): a change above 25% of the larger value
// lowers the hysteresis by 0.15; above 80% the distribution is taken as new (hysteresis 0).
// Compared on encoded values, the space the blend runs in.
float probeAdjustHysteresis(vec3 oldStored, vec3 freshStored, float hysteresis) {
  vec3 delta = abs(freshStored - oldStored);
  float change = max(delta.x, max(delta.y, delta.z));
  vec3 top = max(oldStored, freshStored);
  float scale = max(max(top.x, max(top.y, top.z)), 1e-6f);
  float h = hysteresis;
  if (change > 0.25f * scale) h = max(0.0f, h - 0.15f);
  if (change > 0.8f * scale) h = 0.0f;
  return h;
}

// The distance a probe ray records (M21 Sec. 4.1, end): misses record maxDistance; backface hits
// are shortened to `backfaceScale` (0.2) of their length so the probe sees them as occluders.
float probeRayDepth(float hitT, bool hit, bool backface, float maxDistance, float backfaceScale) {
  if (!hit) return maxDistance;
  float t = min(hitT, maxDistance);
  return backface ? t * backfaceScale : t;
}

// ---- Sampling weights (M21 Sec. 2.2 and 4.1; H22 Sec. 4.4) ------------------------------------

// Chebyshev visibility (H22 Eqs. 4.5-4.9, variance shadow maps): from the depth moments
// (mean, mean of squares) seen by the probe towards the receiver and the receiver's distance r:
// 1 when r <= mean; beyond, the one-tailed bound  var / (var + (r - mean)²)  cubed (Majercik
// 2019's sharpening). The variance is clamped to >= minVariance so that a converged, noise-free
// texel (var = 0, or slightly negative from rounding) gives a finite, steep fall-off.
float probeChebyshevWeight(vec2 moments, float r, float minVariance) {
  float mean = moments.x;
  if (r <= mean) return 1.0f;
  float variance = max(moments.y - mean * mean, minVariance);
  float d = r - mean;
  float w = variance / (variance + d * d);
  return w * w * w;
}

// Backface (wrap) weight (M21 Sec. 2.2 "backface weight"; the formula of Majercik 2019 / RTXGI):
// ((dot(dirToProbe, n) + 1) / 2)² + 0.2. Smooth, never zero, small for probes behind the surface.
float probeBackfaceWeight(vec3 dirToProbe, vec3 n) {
  float w = (dot(dirToProbe, n) + 1.0f) * 0.5f;
  return w * w + 0.2f;
}

// Trilinear weight of cage corner `corner` (bit 0: +x, bit 1: +y, bit 2: +z) for the receiver's
// fractional position alpha in [0,1]³ between the base probe and the opposite one.
float probeTrilinearWeight(vec3 alpha, uint corner) {
  vec3 offset = vec3(float(corner & 1u), float((corner >> 1u) & 1u), float((corner >> 2u) & 1u));
  vec3 w = mix(vec3(1.0f) - alpha, alpha, offset);
  return w.x * w.y * w.z;
}

// Self-shadow bias (M21 Sec. 4.1, Eq. 2): the receiver is moved, for the visibility test only, by
//   (n * 0.2 + view * 0.8) * (0.75 * minAxialSpacing) * biasScale
// n: unit surface normal; view: unit direction from the receiver towards the camera (omega_o);
// minAxialSpacing: D, the smallest probe spacing of the volume; biasScale: B (default 0.3).
vec3 probeSelfShadowBias(vec3 n, vec3 view, float minAxialSpacing, float biasScale) {
  return (n * 0.2f + view * 0.8f) * (0.75f * minAxialSpacing * biasScale);
}

// Low-weight crush (H22 Eq. 4.10: multiply by w² / c² below c; Majercik 2019 uses c = 0.2):
// w < c becomes w³ / c², continuous at c, so barely visible probes fade out instead of leaking.
float probeCrushWeight(float w, float threshold) {
  return w < threshold ? w * (w * w) / (threshold * threshold) : w;
}
