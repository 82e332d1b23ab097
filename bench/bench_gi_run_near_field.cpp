// --diagnose of `bench gi`, the near-field part (bench/bench_gi_config_run.h): an oracle of a
// short per-receiver gather on the triangles, and the SDF version's gap to it taken apart. The
// rest of the diagnosis is bench_gi_run_diagnose.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "bench/bench_gi_config_run.h"
#include "bench/bench_gi_diagnose.h"
#include "demo/frame_image.h"
#include "gi/light_cache.h"
#include "reference/metrics.h"
#include "reference/path_tracer.h"
#include "shaders/shared/color_codec.h"
#include "world/triangle_scene.h"

namespace sdfstream::bench {
namespace {
// "relMSE / E/E_ref" of irradiances e against ref, point by point.
std::string relMseAndRatio(std::span<const glm::vec3> e, std::span<const glm::vec3> ref) {
  double sum = 0, sumRef = 0;
  for (const glm::vec3& x : e) sum += luminance(x);
  for (const glm::vec3& x : ref) sumRef += luminance(x);
  char c[64];
  std::snprintf(c, sizeof c, "%.4f / %.3f", reference::relMSE(e, ref),
                sumRef > 0 ? sum / sumRef : 0.0);
  return c;
}
}  // namespace

// --diagnose: a near-field gather from the receivers, as an oracle on the triangles
// (bench_gi_config_run.h). Radiance along a ray that leaves R free is taken as the irradiance at
// the ray's end facing back along the ray, over pi (exact where the radiance there is uniform).
void ConfigRun::diagnoseNearField(SceneReport& into) {
  if (sc_.points.reference.empty()) return;
  const CascadeStackImage img = st_.stack->stackImage();
  const probe::ProbeFieldFrame f = frameConstants(img);
  const std::vector<std::uint32_t> picks = samplingCascades(f.volumes, sc_.queries);
  const std::size_t stride = std::max<std::size_t>(1, sc_.queries.size() / 512);
  constexpr int kSide = 8;  // K = 64 stratified cosine directions
  constexpr int kRays = kSide * kSide;
  EmbreeScene embree(*sc_.scene.triangles);
  const reference::PathTracer tracer(*sc_.scene.triangles, sc_.scene.lights);
  const std::vector<glm::vec3> giHere = gi_.irradiance(sc_.queries);
  std::vector<std::size_t> receivers;
  for (std::size_t i = 0; i < sc_.queries.size(); i += stride) receivers.push_back(i);
  const double toStack = 1.0 / img.voxelSize0;
  std::string s =
      "\nA near-field gather from the receivers (oracle on the triangles: 64 cosine rays per "
      "receiver to R; hits bring emission + albedo/pi x (delta lights + irradiance at the hit), "
      "misses the irradiance at the ray's end facing back, over pi):\n\n| R (probe spacings) | "
      "receivers | rays hit within R | GI sampled | near: our field | near: reference at "
      "hits, our field beyond | near: reference everywhere | near hits + one query along the bent "
      "normal | the same from 16 rays |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const float spacings : {0.5f, 1.0f, 2.0f}) {
    const std::size_t m = receivers.size();
    std::vector<std::uint8_t> hitKind(m * kRays, 0);              // 0 miss, 1 hit
    std::vector<glm::vec3> hitLight(m * kRays, glm::vec3(0.0f));  // emission + albedo/pi E_direct
    std::vector<glm::vec3> hitAlbedo(m * kRays, glm::vec3(0.0f));
    std::vector<glm::vec3> atPos(m * kRays), atNrm(m * kRays);
    std::vector<gpu_shared::ProbeQuery> atQuery(m * kRays);
    std::vector<glm::vec3> rayDir(m * kRays);
    tbb::parallel_for(std::size_t(0), m, [&](std::size_t r) {
      const std::size_t i = receivers[r];
      const glm::vec3 n = glm::normalize(glm::vec3(sc_.queries[i].normal));
      const glm::vec3 x = sc_.points.position[i] + n * float(0.01 * img.voxelSize0);
      const float reach =
          float(double(spacings) * f.volumes[picks[i]].originSpacing.w * img.voxelSize0);
      const glm::vec3 t = std::abs(n.x) < 0.9f ? glm::normalize(glm::cross(n, {1, 0, 0}))
                                               : glm::normalize(glm::cross(n, {0, 1, 0}));
      const glm::vec3 b = glm::cross(n, t);
      const float rot = float(r % 97) * 0.0647f;  // a per-receiver turn of the strata
      for (int k = 0; k < kRays; ++k) {
        const float u = (float(k % kSide) + 0.5f) / kSide, v = (float(k / kSide) + 0.5f) / kSide;
        const float rad = std::sqrt(u), phi = 6.2831853f * (v + rot);
        const glm::vec3 d = glm::normalize(t * (rad * std::cos(phi)) + b * (rad * std::sin(phi)) +
                                           n * std::sqrt(std::max(0.0f, 1.0f - u)));
        const std::size_t j = r * kRays + k;
        rayDir[j] = d;
        const auto hit = embree.intersect(x, d, 0.0f, reach);
        glm::vec3 p, pn;
        if (hit) {
          pn = hit->normal;
          if (glm::dot(pn, d) > 0.0f) pn = -pn;
          p = x + d * hit->t + pn * float(0.01 * img.voxelSize0);
          const glm::vec3 albedo(sampleAlbedo(*sc_.scene.triangles, hit->triangle, hit->bary));
          hitKind[j] = 1;
          hitAlbedo[j] = albedo;
          hitLight[j] = sampleEmission(*sc_.scene.triangles, hit->triangle, hit->bary) +
                        albedo * tracer.directIrradiance(p, pn) * 0.3183098861837907f;
        } else {
          p = x + d * reach;
          pn = d;
        }
        atPos[j] = p;
        atNrm[j] = pn;
        const glm::vec3 st = glm::vec3((glm::dvec3(p) - img.cascade0MinWorld) * toStack);
        atQuery[j] = {glm::vec4(st, 0.0f), glm::vec4(pn, 0.0f), glm::vec4(pn, 0.0f)};
      }
    });
    // The cheap far term: one query per receiver along its bent normal (the mean free
    // direction), R out, scaled by the free fraction of the cosine-weighted rays.
    std::vector<gpu_shared::ProbeQuery> bentQuery(m);
    std::vector<float> freeFraction(m);
    for (std::size_t r = 0; r < m; ++r) {
      glm::vec3 bent(0.0f);
      int free = 0;
      for (int k = 0; k < kRays; ++k)
        if (!hitKind[r * kRays + k]) {
          bent += glm::normalize(atPos[r * kRays + k] - sc_.points.position[receivers[r]]);
          ++free;
        }
      const std::size_t i = receivers[r];
      const glm::vec3 n(sc_.queries[i].normal);
      bent = free > 0 ? glm::normalize(bent) : n;
      freeFraction[r] = float(free) / float(kRays);
      const float reach = spacings * f.volumes[picks[i]].originSpacing.w;  // stack voxels
      bentQuery[r] = {glm::vec4(glm::vec3(sc_.queries[i].position) + bent * reach, 0.0f),
                      glm::vec4(bent, 0.0f), glm::vec4(bent, 0.0f)};
    }
    const std::vector<glm::vec3> bentE = gi_.irradiance(bentQuery);
    const std::vector<glm::vec3> ours = gi_.irradiance(atQuery);
    const std::vector<glm::vec3> exact = referenceAt(atPos, atNrm);
    std::vector<glm::vec3> sampled(m), ref(m), nearOurs(m), nearMixed(m), nearExact(m), nearBent(m),
        nearBent16(m);
    std::size_t hits = 0;
    for (std::size_t r = 0; r < m; ++r) {
      glm::vec3 a(0.0f), bsum(0.0f), c(0.0f), hitSum(0.0f), hitSum16(0.0f);
      int free16 = 0;
      for (int k = 0; k < kRays; ++k) {
        const std::size_t j = r * kRays + k;
        // Every fourth stratum row and column pair: 16 of the 64 rays.
        const bool in16 = (k % kSide) % 2 == 0 && (k / kSide) % 2 == 0;
        if (hitKind[j]) {
          ++hits;
          const glm::vec3 lh = hitLight[j] + hitAlbedo[j] * ours[j] * 0.3183098861837907f;
          hitSum += lh;
          if (in16) hitSum16 += lh;
          a += hitLight[j] + hitAlbedo[j] * ours[j] * 0.3183098861837907f;
          bsum += hitLight[j] + hitAlbedo[j] * exact[j] * 0.3183098861837907f;
          c += hitLight[j] + hitAlbedo[j] * exact[j] * 0.3183098861837907f;
        } else {
          free16 += in16;
          a += ours[j] * 0.3183098861837907f;
          bsum += ours[j] * 0.3183098861837907f;
          c += exact[j] * 0.3183098861837907f;
        }
      }
      const float scale = 3.14159265f / float(kRays);
      nearOurs[r] = a * scale;
      nearMixed[r] = bsum * scale;
      nearExact[r] = c * scale;
      nearBent[r] = hitSum * scale + freeFraction[r] * bentE[r];
      nearBent16[r] = hitSum16 * (3.14159265f / 16.0f) + float(free16) / 16.0f * bentE[r];
      sampled[r] = giHere[receivers[r]];
      ref[r] = sc_.points.reference[receivers[r]];
    }
    auto cell = [&](const std::vector<glm::vec3>& e) {
      std::string text = " ";
      text += relMseAndRatio(e, ref);
      return text + " |";
    };
    char head[96];
    std::snprintf(head, sizeof head, "| %.1f | %zu | %.1f%% |", spacings, m,
                  100.0 * double(hits) / double(m * kRays));
    const std::string row = head + cell(sampled) + cell(nearOurs) + cell(nearMixed) +
                            cell(nearExact) + cell(nearBent) + cell(nearBent16) + "\n";
    std::printf("    diagnose: near field (relMSE / E/E_ref) %s", row.c_str());
    s += row;
    if (spacings == 1.0f)
      s += nearFieldApart(img, f, picks, receivers, rayDir, hitKind, atPos, atNrm, hitAlbedo, ours,
                          ref, spacings);
  }
  into.diagnosis += s;
}

// The SDF version's gap to the oracle, taken apart (diagnoseNearField, R = 1 spacing): the
// oracle's triangles with the light cache's cell at each hit instead of the exact direct light;
// the SDF version's own rays (from one voxel off the receiver, through the stack) with the exact
// direct light at their hits; and with the light cache's cells (what the sampling pass's
// near-field variant computes).
std::string ConfigRun::nearFieldApart(
    const CascadeStackImage& img, const probe::ProbeFieldFrame& f,
    std::span<const std::uint32_t> picks, std::span<const std::size_t> receivers,
    std::span<const glm::vec3> rayDir, std::span<const std::uint8_t> hitKind,
    std::span<const glm::vec3> atPos, std::span<const glm::vec3> atNrm,
    std::span<const glm::vec3> hitAlbedo, std::span<const glm::vec3> ours,
    std::span<const glm::vec3> ref, float spacings) {
  constexpr float kInvPi = 0.3183098861837907f;
  const std::size_t m = receivers.size(), rays = rayDir.size() / std::max<std::size_t>(1, m);
  const std::vector<std::uint32_t> light = gi_.lightCache().downloadRadiance();
  const reference::PathTracer tracer(*sc_.scene.triangles, sc_.scene.lights);
  const double toStack = 1.0 / img.voxelSize0;
  // The finest cascade whose window holds a stack point.
  auto cascadeOf = [&](glm::vec3 p) {
    for (std::uint32_t c = 0; c < img.params.size(); ++c) {
      const glm::vec3 q = (p - glm::vec3(img.params[c].offsetScale)) / img.params[c].offsetScale.w;
      if (glm::all(glm::greaterThanEqual(q, glm::vec3(0.0f))) &&
          glm::all(glm::lessThanEqual(q, glm::vec3(128.0f))))
        return c;
    }
    return std::uint32_t(img.params.size() - 1);
  };
  auto cacheAt = [&](glm::vec3 p, std::uint32_t c) -> std::optional<glm::vec3> {
    const std::int64_t mat = lightMaterialAt(img, c, p);
    if (mat < 0 || std::size_t(mat) >= light.size()) return std::nullopt;
    return gpu_shared::unpackRgb9e5(light[std::size_t(mat)]);
  };
  // Triangles, the light cache's cell at the SDF's surface by each hit.
  std::vector<glm::vec3> triCache(m, glm::vec3(0.0f));
  std::size_t noCell = 0;
  for (std::size_t r = 0; r < m; ++r) {
    glm::vec3 sum(0.0f);
    for (std::size_t k = 0; k < rays; ++k) {
      const std::size_t j = r * rays + k;
      if (!hitKind[j]) {
        sum += ours[j] * kInvPi;
        continue;
      }
      const glm::vec3 sp((glm::dvec3(atPos[j]) - img.cascade0MinWorld) * toStack +
                         glm::dvec3(atNrm[j]) * 0.5);
      const auto cell = cacheAt(sp, cascadeOf(sp));
      noCell += !cell;
      sum += cell.value_or(glm::vec3(0.0f)) + hitAlbedo[j] * ours[j] * kInvPi;
    }
    triCache[r] = sum * (3.14159265f / float(rays));
  }
  // The first SDF version's rays: from one voxel of the receiver's cascade off it along the
  // normal, through the stack (the shader now starts at the receiver and skips the proud shell
  // along each ray; this diagnosis keeps the first start, which measured what it costs).
  std::vector<gpu_shared::TraceRay> traced(m * rays);
  std::vector<std::uint32_t> first(m * rays, 0u);
  std::vector<float> reachOf(m);
  for (std::size_t r = 0; r < m; ++r) {
    const gpu_shared::ProbeQuery& q = sc_.queries[receivers[r]];
    const std::uint32_t c = picks[receivers[r]];
    const glm::vec3 o = glm::vec3(q.position) + glm::vec3(q.normal) * img.params[c].offsetScale.w;
    reachOf[r] = spacings * f.volumes[c].originSpacing.w;
    for (std::size_t k = 0; k < rays; ++k) {
      traced[r * rays + k].originTMin = glm::vec4(o, 0.0f);
      traced[r * rays + k].dirTMax = glm::vec4(rayDir[r * rays + k], reachOf[r]);
    }
  }
  EmbreeScene embree(*sc_.scene.triangles);
  const std::vector<gpu_shared::TraceHit> hits =
      traceFromCascades(peerInputs(embree), traced, first);
  std::vector<gpu_shared::ProbeQuery> q(m * rays);
  for (std::size_t j = 0; j < q.size(); ++j) {
    const glm::vec3 o(traced[j].originTMin), d(traced[j].dirTMax);
    const bool hit = (hits[j].flags & gpu_shared::kHitFlagHit) != 0u;
    const glm::vec3 at = o + d * (hit ? hits[j].normalT.w : traced[j].dirTMax.w);
    const glm::vec3 n = hit ? glm::vec3(hits[j].normalT) : d;
    q[j] = {glm::vec4(at, 0.0f), glm::vec4(n, 0.0f), glm::vec4(hit ? -d : d, 0.0f)};
  }
  const std::vector<glm::vec3> fieldAt = gi_.irradiance(q);
  std::vector<glm::vec3> sdfExact(m, glm::vec3(0.0f)), sdfCache(m, glm::vec3(0.0f));
  std::size_t sdfHits = 0, total = 0;
  for (std::size_t r = 0; r < m; ++r) {
    glm::vec3 a(0.0f), b(0.0f);
    std::uint32_t used = 0;
    for (std::size_t k = 0; k < rays; ++k) {
      const std::size_t j = r * rays + k;
      const glm::vec3 d(traced[j].dirTMax);
      const bool hit = (hits[j].flags & gpu_shared::kHitFlagHit) != 0u;
      if (hit && hits[j].normalT.w < 0.5f) continue;
      ++used;
      if (!hit) {
        a += fieldAt[j] * kInvPi;
        b += fieldAt[j] * kInvPi;
        continue;
      }
      ++sdfHits;
      const glm::vec3 n(hits[j].normalT);
      if (glm::dot(n, d) >= 0.0f) continue;
      const std::uint32_t al = hits[j].albedo;
      const glm::vec3 albedo = reference::srgbToLinear(
          glm::vec3(float(al & 255u), float(al >> 8 & 255u), float(al >> 16 & 255u)) / 255.0f);
      const glm::vec3 h = glm::vec3(q[j].position);
      const glm::vec3 world(img.cascade0MinWorld + glm::dvec3(h + n * 0.05f) * img.voxelSize0);
      const glm::vec3 bounce = albedo * fieldAt[j] * kInvPi;
      a += gpu_shared::unpackRgb9e5(hits[j].emission) +
           albedo * tracer.directIrradiance(world, n) * kInvPi + bounce;
      const std::uint32_t hc = (hits[j].flags >> gpu_shared::kHitCascadeShift) & 15u;
      b += cacheAt(h, hc).value_or(glm::vec3(0.0f)) + bounce;
    }
    total += used;
    const float scale = used > 0 ? 3.14159265f / float(used) : 0.0f;
    sdfExact[r] = a * scale;
    sdfCache[r] = b * scale;
  }
  auto cell = [&](const std::vector<glm::vec3>& e) { return relMseAndRatio(e, ref); };
  // Embree's verdict on the SDF's rays: the same rays (start, direction, reach) on the
  // triangles, lit exactly, and each ray's radiance on both sides by what the two saw.
  std::vector<std::optional<EmbreeScene::Hit>> tri(m * rays);
  std::vector<gpu_shared::ProbeQuery> qt(m * rays);
  std::vector<glm::vec3> triNormal(m * rays, glm::vec3(0.0f));
  tbb::parallel_for(std::size_t(0), m * rays, [&](std::size_t j) {
    const glm::vec3 o(traced[j].originTMin), d(traced[j].dirTMax);
    const float reach = traced[j].dirTMax.w;
    const glm::vec3 ow(img.cascade0MinWorld + glm::dvec3(o) * img.voxelSize0);
    tri[j] = embree.intersect(ow, d, 0.0f, float(double(reach) * img.voxelSize0));
    glm::vec3 at = o + d * reach, n = d;
    if (tri[j]) {
      n = tri[j]->normal;
      if (glm::dot(n, d) > 0.0f) n = -n;
      at = o + d * float(double(tri[j]->t) / img.voxelSize0) + n * 0.05f;
      triNormal[j] = n;
    }
    qt[j] = {glm::vec4(at, 0.0f), glm::vec4(n, 0.0f), glm::vec4(n, 0.0f)};
  });
  const std::vector<glm::vec3> fieldTri = gi_.irradiance(qt);
  enum { kBothMiss, kBothHit, kSdfOnly, kTriOnly, kKinds };
  std::array<std::size_t, kKinds> kindRays{};
  // The SDF's hits by the cascade they land in, and how far from the start the ray's cascade
  // is: where the SDF alone hits against where both do.
  std::vector<std::size_t> sdfOnlyBy(img.params.size(), 0), bothBy(img.params.size(), 0);
  std::array<double, kKinds> kindSdf{}, kindTri{};
  std::vector<glm::vec3> triFromStart(m, glm::vec3(0.0f));
  for (std::size_t r = 0; r < m; ++r) {
    glm::vec3 sum(0.0f);
    std::uint32_t used = 0;
    for (std::size_t k = 0; k < rays; ++k) {
      const std::size_t j = r * rays + k;
      const glm::vec3 d(traced[j].dirTMax);
      const bool sdfHit = (hits[j].flags & gpu_shared::kHitFlagHit) != 0u;
      const bool triHit = tri[j].has_value();
      // Each side's radiance along the ray, as sdfExact and the oracle take it.
      glm::vec3 lt(0.0f);
      if (triHit) {
        const glm::vec3 world(img.cascade0MinWorld +
                              glm::dvec3(glm::vec3(qt[j].position)) * img.voxelSize0);
        const glm::vec3 albedo(sampleAlbedo(*sc_.scene.triangles, tri[j]->triangle, tri[j]->bary));
        lt = sampleEmission(*sc_.scene.triangles, tri[j]->triangle, tri[j]->bary) +
             albedo * (tracer.directIrradiance(world, triNormal[j]) + fieldTri[j]) * kInvPi;
      } else {
        lt = fieldTri[j] * kInvPi;
      }
      if (!(triHit && double(tri[j]->t) < 0.5 * img.voxelSize0)) {
        sum += lt;
        ++used;
      }
      glm::vec3 ls(0.0f);
      if (!sdfHit) {
        ls = fieldAt[j] * kInvPi;
      } else if (glm::dot(glm::vec3(hits[j].normalT), d) < 0.0f) {
        const std::uint32_t al = hits[j].albedo;
        const glm::vec3 albedo = reference::srgbToLinear(
            glm::vec3(float(al & 255u), float(al >> 8 & 255u), float(al >> 16 & 255u)) / 255.0f);
        const glm::vec3 n(hits[j].normalT), h(q[j].position);
        const glm::vec3 world(img.cascade0MinWorld + glm::dvec3(h + n * 0.05f) * img.voxelSize0);
        ls = gpu_shared::unpackRgb9e5(hits[j].emission) +
             albedo * (tracer.directIrradiance(world, n) + fieldAt[j]) * kInvPi;
      }
      const int kind = sdfHit ? (triHit ? kBothHit : kSdfOnly) : (triHit ? kTriOnly : kBothMiss);
      ++kindRays[kind];
      if (sdfHit) {
        const std::uint32_t hc =
            std::min<std::uint32_t>((hits[j].flags >> gpu_shared::kHitCascadeShift) & 15u,
                                    std::uint32_t(img.params.size() - 1));
        ++(triHit ? bothBy : sdfOnlyBy)[hc];
      }
      kindSdf[kind] += luminance(ls);
      kindTri[kind] += luminance(lt);
    }
    triFromStart[r] = used > 0 ? sum * (3.14159265f / float(used)) : glm::vec3(0.0f);
  }
  std::string kinds;
  const char* kindName[kKinds] = {"both miss", "both hit", "the SDF only hits",
                                  "the triangles only hit"};
  for (int k = 0; k < kKinds; ++k) {
    char c[160];
    std::snprintf(c, sizeof c, "%s%s %.1f%% of the rays, mean radiance SDF %.4g / triangles %.4g",
                  k ? "; " : "", kindName[k],
                  100.0 * double(kindRays[k]) / double(std::max<std::size_t>(1, m * rays)),
                  kindRays[k] ? kindSdf[k] / double(kindRays[k]) : 0.0,
                  kindRays[k] ? kindTri[k] / double(kindRays[k]) : 0.0);
    kinds += c;
  }
  kinds += ". The SDF's hits by the cascade they land in (the SDF only / both):";
  for (std::size_t c = 0; c < img.params.size(); ++c) {
    if (sdfOnlyBy[c] + bothBy[c] == 0) continue;
    char c2[64];
    std::snprintf(c2, sizeof c2, " %zu: %zu / %zu;", c, sdfOnlyBy[c], bothBy[c]);
    kinds += c2;
  }
  char row[2000];
  std::snprintf(
      row, sizeof row,
      "\nThe SDF version's gap, taken apart at R = 1 spacing (relMSE / E/E_ref): the "
      "triangles with the light cache's cell at each hit %s (%zu hits without a "
      "resident cell); the triangles from the first SDF version's start (one voxel off), "
      "exact light, %s; the SDF's own rays from there (through the stack; %.1f%% hit) with the "
      "exact direct light %s, with the light cache's cells %s. Ray by ray against the "
      "triangles from the same start: %s.\n",
      cell(triCache).c_str(), noCell, cell(triFromStart).c_str(),
      100.0 * double(sdfHits) / double(std::max<std::size_t>(1, total)), cell(sdfExact).c_str(),
      cell(sdfCache).c_str(), kinds.c_str());
  std::printf("    diagnose:%s", row + 1);
  return row;
}

}  // namespace sdfstream::bench
