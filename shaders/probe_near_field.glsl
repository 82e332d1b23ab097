// The near-field gather (probe_sample.comp's near-field variant; shaders/probe_field.glsl lists
// the pass files): a receiver's irradiance from a few short rays of its own instead of the probe
// cage alone. Reads what sampling reads, plus LIGHT_RADIANCE and SDF_ALBEDO (after
// shaders/probe_trace.glsl: probeBounceTerm).
//
// Why: one probe spacing off their surfaces the field is as good as its grid allows, and on
// them it is not (Sponza, `bench gi --quick --diagnose`: relMSE 0.068 one spacing out, 0.189 on
// the surfaces). What a grid cannot hold is the light's variation within a spacing of a surface:
// contact occlusion and the nearby walls' bounce. Lumen's screen probes trace a short near field
// and hand the rest to the distant lighting; here each of K cosine-distributed rays is traced
// through the SDF stack to R = reach x the probe spacing of the receiver's cascade:
//  - a front hit brings the light cache's radiance (emission + direct light) plus the multi-bounce
//    term albedo x E / pi, E the field's irradiance at the hit (as probeShadeRay in
//    shaders/probe_trace.glsl, but with the SDF visibility test where the settings have it:
//    Breakfast Room relMSE 0.128 -> 0.117 in `bench gi --quick`);
//  - a backface hit (the ray started inside geometry) brings nothing; a hit within half a voxel
//    of the ray's start (a receiver in a crease) is left out, and a receiver with every ray left
//    out reads the field as plain sampling does;
//  - a miss brings the field's irradiance at the ray's end, facing back along the ray, over pi:
//    the radiance arriving along the ray, exact where the light there is uniform (SDF
//    visibility as sampling has it: 0.149 -> 0.128 there).
// E = pi / K' x the sum over the K' rays not left out (cosine-weighted directions).
//
// An oracle of the same estimator on the triangles (bench gi --diagnose) gave Sponza relMSE
// 0.129 -> 0.038 and E/E_ref 0.915 -> 0.975 at R = 1 spacing, 64 rays. Through the SDF it does
// less (the SDF's near geometry, measured apart from the light cache), costs the Cornell box
// and the Breakfast Room accuracy, and is ~170x the sampling pass on an H100 (16 rays, 1080p:
// 259 ms). So it is off by default (ProbeFieldSettings::nearFieldRays; docs/DECISIONS.md, "A
// near-field gather"; docs/GPU_BUDGET.md). Starting the rays at the receiver (below) instead of
// a voxel off it took 16 rays' quick-mode relMSE from 0.1265 to 0.1077 (Breakfast Room) and
// 0.1518 to 0.1464 (Sponza; the default without it 0.2028), 0.0209 to 0.0220 (Cornell box).

// ProbeFrame::bounce.w: bits 0-7 rays per query (0: off), bits 8-15 the reach in eighths of a
// probe spacing.
uint probeNearFieldRays(ProbeFrame f) {
  return f.bounce.w & 0xffu;
}

float probeNearFieldReach(ProbeFrame f) {
  return float((f.bounce.w >> 8u) & 0xffu) * 0.125f;
}

// The finest cascade whose probe grid holds x, as probeFieldIrradiance picks it.
uint probeNearFieldCascade(ProbeFrame f, vec3 x) {
  for (uint c = 0u; c + 1u < f.counts.x; ++c)
    if (probeCascadeShare(f, c, x) >= 0.0f) return c;
  return f.counts.x - 1u;
}

// A turn of the ray pattern per receiver and field update, from the receiver's position bits:
// the same on the GPU and in the CPU reference, different for neighbouring pixels.
float probeNearFieldTurn(ProbeFrame f, vec3 x) {
  uint h = floatBitsToUint(x.x) * 0x9E3779B1u;
  h = (h ^ floatBitsToUint(x.y)) * 0x85EBCA77u;
  h = (h ^ floatBitsToUint(x.z)) * 0xC2B2AE3Du;
  h ^= f.options.y * 0x27D4EB2Fu;
  h ^= h >> 15u;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12u;
  return float(h >> 8u) * (1.0f / 16777216.0f);
}

// Ray k of K: a cosine-distributed spiral (equal areas of the projected disk, golden-angle
// turns), turned by `turn`, about unit normal n.
vec3 probeNearFieldDirection(vec3 n, uint k, uint count, float turn) {
  vec3 t = abs(n.x) < 0.9f ? normalize(cross(n, vec3(1.0f, 0.0f, 0.0f)))
                           : normalize(cross(n, vec3(0.0f, 1.0f, 0.0f)));
  vec3 b = cross(n, t);
  float u = (float(k) + 0.5f) / float(count);
  float r = sqrt(u);
  float phi = 6.2831853f * fract(float(k) * 0.61803399f + turn);
  return normalize(t * (r * cos(phi)) + b * (r * sin(phi)) + n * sqrt(max(0.0f, 1.0f - u)));
}

// The near-field gather at receiver x (cascade-0 voxels) with unit normal n.
vec3 probeNearFieldIrradiance(ProbeFrame f, vec3 x, vec3 n) {
  uint count = probeNearFieldRays(f);
  uint c = probeNearFieldCascade(f, x);
  float reach = probeNearFieldReach(f) * PROBE_VOLUME(c).originSpacing.w;
  float turn = probeNearFieldTurn(f, x);
  // The rays start at the receiver. It lies on the triangles, inside the SDF's surface where that
  // stands proud (an open sheet's shell by half a voxel, a coarse cascade's min-filtered surface
  // by up to one of its voxels), where every ray would hit at once. So each ray skips the depth
  // the receiver lies inside, plus half a voxel of the cascade, over its cosine to the normal:
  // where a flat proud surface ends along that ray. Starting one voxel off along the normal
  // instead (the first version) lost contact occlusion: the oracle on the triangles from that
  // start read the Breakfast Room's relMSE 0.0870 against 0.0510 from the receiver.
  vec3 o = x + n * 0.05f;
  ProbeSdf at = probeSdfAt(0u, f.counts.x, o);
  float inside = max(0.0f, -at.distance) + 0.5f * SDF_CASCADE(c).offsetScale.w;
  vec3 sum = vec3(0.0f);
  uint used = 0u;
  for (uint k = 0u; k < count; ++k) {
    vec3 d = probeNearFieldDirection(n, k, count, turn);
    float tStart = min(inside / max(dot(d, n), 0.25f), 0.5f * reach);
    SdfStackResult s =
        sdfTraceStackFrom(o, d, tStart, reach, f.options.w, f.trace.x, 0u, f.counts.x);
    // A hit within half a voxel: the receiver sits in a concave crease, a hair from the other
    // face, where the hit's cell and normal belong to both faces (a white furnace's receiver
    // 0.04 voxel from a second wall read 50% dark, or, every ray hitting at once, black). Such
    // rays say nothing the SDF can resolve; the others stand for them.
    if (s.r.hit && s.t0 < tStart + 0.5f) continue;
    used += 1u;
    if (s.r.hit) {
      vec3 hn = sdfNormal(s.r.position, SDF_CASCADE(s.cascade).toroidal);
      if (dot(hn, d) >= 0.0f) continue;  // a backface: the ray started inside geometry
      uint material = s.r.slot * kBrickMaterialCount + s.r.cell;
      vec3 e = probeFieldIrradiance(f, o + d * s.t0, hn, -d, true, -1);
      sum += unpackRgb9e5(LIGHT_RADIANCE(material)) + probeBounceTerm(f, material, e);
    } else {
      sum += probeFieldIrradiance(f, o + d * reach, d, d, true, -1) * 0.3183098861837907f;
    }
  }
  // Every ray left out (a receiver on a surface at the start, as where a crease's two faces
  // meet): the field as sampling reads it without a near field.
  if (used == 0u) return probeFieldIrradiance(f, x, n, n, true, -1);
  return sum * (3.14159265f / float(used));
}
