// --diagnose of `bench gi` (bench/bench_gi_diagnose.h has the tables' meaning): the members of
// ConfigRun that measure where the light goes, run after a configuration has converged.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <span>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "bench/bench_gi_config_run.h"
#include "bench/bench_gi_diagnose.h"
#include "demo/frame_image.h"
#include "gi/light_cache.h"
#include "gi/probe_math.h"
#include "gi/scene_lights.h"
#include "reference/metrics.h"
#include "reference/path_tracer.h"
#include "world/triangle_scene.h"

namespace sdfstream::bench {
namespace {
// The six axis normals the probes' irradiance is compared along.
const glm::vec3 kAxes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

}  // namespace

// --diagnose: this frame's probe rays against Embree, by the cascade they end in.
void ConfigRun::diagnoseRays(SceneReport& into) {
  into.diagnosis += "Configuration taken apart: `" + cfg_.name + "`.\n\n";
  const CascadeStackImage img = st_.stack->stackImage();
  const PeerRays rays = probeRaySet(gi_, img, cfg_.probes, in_, frame_);
  EmbreeScene embree(*sc_.scene.triangles);
  const PeerInputs pi = peerInputs(embree);
  const ProbeRayDiagnosis d = diagnoseProbeRays(pi, rays);
  std::string nearText;
  // The same for the rays of the probes the receivers use (their cages in their sampling
  // cascade): the light a receiver gets comes through these.
  {
    const probe::ProbeFieldFrame f = frameConstants(img);
    const std::vector<std::uint32_t> picks = samplingCascades(f.volumes, sc_.queries);
    std::vector<std::vector<char>> cage(f.volumes.size());
    for (std::size_t c = 0; c < f.volumes.size(); ++c)
      cage[c].assign(cfg_.probes.probesPerVolume(), 0);
    for (std::size_t i = 0; i < sc_.queries.size(); ++i) {
      const gpu_shared::ProbeVolume& v = f.volumes[picks[i]];
      const glm::ivec3 counts(v.countsRays);
      const glm::ivec3 base = glm::clamp(
          glm::ivec3(glm::floor((glm::vec3(sc_.queries[i].position) - glm::vec3(v.originSpacing)) /
                                v.originSpacing.w)),
          glm::ivec3(0), counts - 2);
      for (int k = 0; k < 8; ++k) {
        const glm::ivec3 l = base + glm::ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        cage[picks[i]][std::size_t(l.x + counts.x * (l.y + counts.y * l.z))] = 1;
      }
    }
    PeerRays near;
    for (std::size_t i = 0; i < rays.origin.size(); ++i) {
      if (!cage[rays.cascade[i]][rays.probeCell[i]]) continue;
      near.stack.push_back(rays.stack[i]);
      near.origin.push_back(rays.origin[i]);
      near.direction.push_back(rays.direction[i]);
      near.tMax.push_back(rays.tMax[i]);
      near.cascade.push_back(rays.cascade[i]);
      near.probeCell.push_back(rays.probeCell[i]);
    }
    if (!near.origin.empty()) {
      const ProbeRayDiagnosis dn = diagnoseProbeRays(pi, near);
      std::printf(
          "    diagnose: rays of the receivers' cage probes: %zu; closed %.1f%%, early "
          "%.1f%%; sky ours %.1f%% vs Embree %.1f%%\n",
          dn.all.rays,
          100.0 * double(dn.all.closed) / double(std::max<std::size_t>(1, dn.all.rays)),
          100.0 * double(dn.all.early) / double(std::max<std::size_t>(1, dn.all.rays)),
          100.0 * dn.skyOurs, 100.0 * dn.skyEmbree);
      nearText = "\nOnly the rays of the probes in the receivers' cages:\n\n" +
                 diagnosisMarkdown(dn, std::size_t(cfg_.cascades)) + "\n";
      for (const SceneLight& l : sc_.scene.lights.lights) {
        if (l.type != SceneLight::Type::Sun) continue;
        const SunAgreement sa = diagnoseSunVisibility(pi, near, img, -glm::normalize(l.direction));
        char line[400];
        std::snprintf(
            line, sizeof line,
            "The sun where those rays land (Embree's hits facing it, %zu): lit on the "
            "triangles %.1f%%; of those, shadowed through our stack %.1f%%; of the "
            "shadowed ones, lit through our stack %.1f%%.\n",
            sa.facing, 100.0 * double(sa.sunlit) / double(std::max<std::size_t>(1, sa.facing)),
            100.0 * double(sa.lost) / double(std::max<std::size_t>(1, sa.sunlit)),
            100.0 * double(sa.gained) / double(std::max<std::size_t>(1, sa.facing - sa.sunlit)));
        std::printf("    diagnose: %s", line);
        nearText += std::string("\n") + line;
      }
    }
  }
  std::printf(
      "    diagnose: %zu probe rays; closed %.1f%%, early %.1f%%, leak %.1f%%, backface "
      "%.1f%%; sky ours %.1f%% vs Embree %.1f%%\n",
      d.all.rays, 100.0 * double(d.all.closed) / double(std::max<std::size_t>(1, d.all.rays)),
      100.0 * double(d.all.early) / double(std::max<std::size_t>(1, d.all.rays)),
      100.0 * double(d.all.leaks) / double(std::max<std::size_t>(1, d.all.rays)),
      100.0 * double(d.all.backfaces) / double(std::max<std::size_t>(1, d.all.rays)),
      100.0 * d.skyOurs, 100.0 * d.skyEmbree);
  into.diagnosis += diagnosisMarkdown(d, std::size_t(cfg_.cascades)) + nearText;
  diagnoseProbeIrradiance(into);
  diagnoseCascadesAlone(into);
  diagnoseAwayFromSurfaces(into, false);
  diagnoseNearField(into);
}

// One frame's probe rays (one more step), each against the same ray on the triangles under
// one-bounce transport: the sky where Embree's ray escapes the scene (unbounded: what lies beyond
// the stack is part of what our rays miss), else emission + albedo/pi x the delta lights (hard
// shadows) at Embree's hit.
ConfigRun::RayComparison ConfigRun::compareRays(const CascadeStackImage& img,
                                                const EmbreeScene& embree) {
  RayComparison c;
  const GiFrameStats stats = step();
  c.rec = gi_.probes().downloadRays(stats.probes.probesUpdated);
  c.frame = frameConstants(img);
  c.probeData = gi_.probes().downloadProbeData();
  const std::uint32_t perVolume = cfg_.probes.probesPerVolume(), n = cfg_.probes.raysPerProbe;
  c.cage = cageProbes(c.frame, perVolume, sc_.queries);
  const auto& rec = c.rec;
  const auto& f = c.frame;
  const auto& data = c.probeData;
  const auto& cage = c.cage;
  const reference::PathTracer tracer(*sc_.scene.triangles, sc_.scene.lights);
  const gpu_shared::GpuSky gpuSky = toGpu(lights_.sky);
  const std::size_t rays = rec.results.size();
  c.ours.assign(rays, 0.0f);
  c.ref.assign(rays, 0.0f);
  c.group.assign(rays, 0);
  c.inCage.assign(rays, 0);
  c.cascadeOf.assign(rays, 0);
  c.triT.assign(rays, -1.0f);
  c.triNormal.assign(rays, glm::vec3(0.0f));
  c.triAlbedo.assign(rays, glm::vec3(0.0f));
  auto& ours = c.ours;
  auto& ref = c.ref;
  auto& group = c.group;
  auto& inCage = c.inCage;
  auto& cascadeOf = c.cascadeOf;
  auto& triT = c.triT;
  auto& triNormal = c.triNormal;
  auto& triAlbedo = c.triAlbedo;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, rec.list.size(), 16),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t l = r.begin(); l != r.end(); ++l) {
          const std::uint32_t g = rec.list[l];
          const LiveProbe p = probeAt(f, perVolume, g, data[g]);
          const bool cageProbe = cage.count(p.cascade * perVolume + p.cell) > 0;
          const float maxDepth = f.volumes[p.cascade].blend.z;
          const glm::vec3 origin(img.cascade0MinWorld + glm::dvec3(p.stack) * img.voxelSize0);
          for (std::uint32_t k = 0; k < n; ++k) {
            const std::size_t i = l * n + k;
            const glm::vec3 dir = glm::normalize(glm::vec3(rec.directions[i]));
            const auto hit = embree.intersect(origin, dir, 0.0f, 1e30f);
            glm::vec3 l1;
            bool lit = false;
            if (hit) {
              glm::vec3 nrm = hit->normal;
              if (glm::dot(nrm, dir) > 0.0f) nrm = -nrm;
              const glm::vec3 x = origin + dir * hit->t;
              const glm::vec3 e = tracer.directIrradiance(x, nrm);
              lit = luminance(e) > 0.0;
              triT[i] = hit->t;
              triNormal[i] = nrm;
              triAlbedo[i] =
                  glm::vec3(sampleAlbedo(*sc_.scene.triangles, hit->triangle, hit->bary));
              l1 = sampleEmission(*sc_.scene.triangles, hit->triangle, hit->bary) +
                   glm::vec3(sampleAlbedo(*sc_.scene.triangles, hit->triangle, hit->bary)) * e *
                       0.3183098861837907f;
            } else {
              l1 = tracer.skyRadianceAlong(dir);
            }
            // A miss records the volume's max depth and the sky; a hit beyond that depth records
            // the max depth too, but not the sky's colour.
            const glm::vec3 sky = skyRadianceCpu(gpuSky, dir), got(rec.results[i]);
            const bool oursSky = std::abs(rec.results[i].w) >= 0.999f * maxDepth &&
                                 glm::length(got - sky) <= 1e-3f * glm::length(sky) + 1e-6f;
            ours[i] = float(luminance(glm::vec3(rec.results[i])));
            ref[i] = float(luminance(l1));
            group[i] =
                std::uint8_t(oursSky ? (hit ? RayComparison::kEmbreeOnly : RayComparison::kSkyBoth)
                                     : (!hit  ? RayComparison::kOursOnly
                                        : lit ? RayComparison::kLitBoth
                                              : RayComparison::kShadowBoth));
            inCage[i] = cageProbe;
            cascadeOf[i] = std::uint8_t(p.cascade);
          }
        }
      });
  return c;
}

// The cage probes' rays that land where the sun reaches on the triangles, taken apart: our
// hit traced again through the stack from the probe, its albedo, SDF normal and a hard
// shadow ray from half a voxel off it towards the sun (as the light cache starts one), and
// albedo/pi x E_sun x cos x visibility built from those -- against what the light cache
// returned and what the triangles give.
void ConfigRun::diagnoseSunlitHits(SceneReport& into, const RayComparison& c,
                                   const CascadeStackImage& img, const EmbreeScene& embree) {
  const auto& rec = c.rec;
  const auto& f = c.frame;
  const auto& data = c.probeData;
  const auto& ours = c.ours;
  const auto& ref = c.ref;
  const auto& group = c.group;
  const auto& inCage = c.inCage;
  const auto& triT = c.triT;
  const auto& triNormal = c.triNormal;
  const auto& triAlbedo = c.triAlbedo;
  const std::uint32_t perVolume = cfg_.probes.probesPerVolume(), n = cfg_.probes.raysPerProbe;
  if (lights_.lights.empty() || lights_.lights[0].type != SceneLight::Type::Sun) return;
  const SceneLight& sun = lights_.lights[0];
  const glm::vec3 toSun = -glm::normalize(sun.direction);
  const glm::vec3 sunE = sun.color * sun.intensity;
  std::vector<std::size_t> idx;
  std::vector<gpu_shared::TraceRay> primary;
  std::vector<std::uint32_t> first;
  for (std::size_t l = 0; l < rec.list.size(); ++l) {
    const std::uint32_t g = rec.list[l];
    const LiveProbe p = probeAt(f, perVolume, g, data[g]);
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::size_t i = l * n + k;
      if (group[i] != RayComparison::kLitBoth || !inCage[i]) continue;
      gpu_shared::TraceRay tr;
      tr.originTMin = glm::vec4(p.stack, 0.0f);
      tr.dirTMax = glm::vec4(glm::normalize(glm::vec3(rec.directions[i])), 1e30f);
      primary.push_back(tr);
      first.push_back(p.cascade);
      idx.push_back(i);
    }
  }
  const PeerInputs pi = peerInputs(embree);
  const std::vector<gpu_shared::TraceHit> hits = traceFromCascades(pi, primary, first);
  std::vector<gpu_shared::TraceRay> shadow(hits.size());
  std::vector<std::uint32_t> shadowFirst(hits.size(), 0);
  for (std::size_t j = 0; j < hits.size(); ++j) {
    const std::uint32_t c = (hits[j].flags >> gpu_shared::kHitCascadeShift) & 15u;
    const glm::vec3 o(primary[j].originTMin), d(primary[j].dirTMax), nrm(hits[j].normalT);
    const glm::vec3 x = o + d * std::max(hits[j].normalT.w, 0.0f);
    shadow[j].originTMin = glm::vec4(x + nrm * (0.5f * img.params[c].offsetScale.w), 0.0f);
    shadow[j].dirTMax = glm::vec4(toSun, 1e9f);
    shadowFirst[j] = c;
  }
  const std::vector<gpu_shared::TraceHit> shadowHits = traceFromCascades(pi, shadow, shadowFirst);
  double cache = 0, model = 0, modelUnshadowed = 0, tri = 0, cosOurs = 0, cosTri = 0, albOurs = 0,
         albTri = 0, visible = 0;
  std::size_t counted = 0, missed = 0, far = 0;
  // By the cascade our hit lands in: the light cache against the model at the hit.
  const std::size_t nc = img.params.size();
  std::vector<double> cacheBy(nc, 0.0), modelBy(nc, 0.0);
  std::vector<std::size_t> countBy(nc, 0), darkBy(nc, 0);
  // Why black cells are black: the light cache's steps for the cell each hit reads.
  const std::vector<gpu_shared::GpuLight> gpuLights = toGpu(lights_.lights, img);
  std::size_t blackOutOfBand = 0, blackFacingAway = 0, blackShadowFiner = 0, blackShadowSame = 0,
              blackOther = 0, shown = 0, blackLitWithMoreSteps[3] = {};
  std::string examples;
  for (std::size_t j = 0; j < hits.size(); ++j) {
    const std::size_t i = idx[j];
    if (!(hits[j].flags & gpu_shared::kHitFlagHit)) {
      ++missed;
      continue;
    }
    {
      const std::uint32_t hc = (hits[j].flags >> gpu_shared::kHitCascadeShift) & 15u;
      const glm::vec3 o(primary[j].originTMin), d(primary[j].dirTMax);
      const glm::vec3 x0 = o + d * hits[j].normalT.w;
      const bool shadowLit = (shadowHits[j].flags &
                              (gpu_shared::kHitFlagHit | gpu_shared::kHitFlagRanOutOfSteps)) == 0u;
      if (ours[i] <= 0.0f && shadowLit && glm::dot(glm::vec3(hits[j].normalT), toSun) > 0.0f) {
        const LightCellSteps st = lightCellSteps(img, gpuLights[0], hc, x0);
        const char* why = "other";
        if (!st.inBand) {
          ++blackOutOfBand;
          why = "out of band";
        } else if (st.cosine <= 0.0f) {
          ++blackFacingAway;
          why = "cell normal faces away";
        } else if (st.visibility <= 0.0f && st.shadowCascade < hc) {
          ++blackShadowFiner;
          why = "shadowed, ray starts in a finer cascade";
        } else if (st.visibility <= 0.0f) {
          ++blackShadowSame;
          why = "shadowed from the cell's surface point";
          for (int b = 0; b < 3; ++b) {
            LightCacheSettings more;
            more.maxShadowSteps = 256u << b;
            if (lightCellSteps(img, gpuLights[0], hc, x0, more).visibility > 0.0f)
              ++blackLitWithMoreSteps[b];
          }
        } else {
          ++blackOther;
        }
        if (shown < 8) {
          ++shown;
          char e[400];
          std::snprintf(e, sizeof e,
                        "  - hit (%.1f %.1f %.1f) cascade %u, hit normal (%.2f %.2f %.2f); "
                        "cell d %.2f, normal (%.2f %.2f %.2f), surface (%.1f %.1f %.1f), "
                        "cos %.2f, shadow from cascade %u, visibility %.2f: %s\n",
                        x0.x, x0.y, x0.z, hc, hits[j].normalT.x, hits[j].normalT.y,
                        hits[j].normalT.z, st.distance, st.normal.x, st.normal.y, st.normal.z,
                        st.surface0.x, st.surface0.y, st.surface0.z, st.cosine, st.shadowCascade,
                        st.visibility, why);
          examples += e;
        }
      }
    }
    if (std::abs(double(hits[j].normalT.w) * img.voxelSize0 - double(triT[i])) >
        4.0 * img.voxelSize0 * img.params[(hits[j].flags >> 8) & 15u].offsetScale.w)
      ++far;
    const std::uint32_t a = hits[j].albedo;
    const glm::vec3 albedo = reference::srgbToLinear(
        glm::vec3(float(a & 255u), float(a >> 8 & 255u), float(a >> 16 & 255u)) / 255.0f);
    const float cos = std::max(0.0f, glm::dot(glm::vec3(hits[j].normalT), toSun));
    const bool lit =
        (shadowHits[j].flags & (gpu_shared::kHitFlagHit | gpu_shared::kHitFlagRanOutOfSteps)) == 0u;
    const glm::vec3 unshadowed = albedo * sunE * cos * 0.3183098861837907f;
    const std::uint32_t hc = std::min<std::uint32_t>(
        (hits[j].flags >> gpu_shared::kHitCascadeShift) & 15u, std::uint32_t(nc - 1));
    cacheBy[hc] += ours[i];
    modelBy[hc] += lit ? luminance(unshadowed) : 0.0;
    ++countBy[hc];
    darkBy[hc] += ours[i] <= 0.0f && lit && cos > 0.0f;
    cache += ours[i];
    model += lit ? luminance(unshadowed) : 0.0;
    modelUnshadowed += luminance(unshadowed);
    tri += ref[i];
    cosOurs += cos;
    cosTri += std::max(0.0f, glm::dot(triNormal[i], toSun));
    albOurs += luminance(albedo);
    albTri += luminance(triAlbedo[i]);
    visible += lit;
    ++counted;
  }
  if (counted > 0) {
    const double c = double(counted);
    char row[900];
    std::snprintf(
        row, sizeof row,
        "\nThe cage probes' rays that land where the sun reaches on the triangles (%zu; %zu "
        "of them miss when traced again, %zu hit more than 4 voxels of their cascade from "
        "Embree's hit), taken apart at our own hit: mean luminance the light cache returned "
        "%.4g; albedo/pi x E_sun x cos x visibility at our hit %.4g (unshadowed %.4g); the "
        "triangles %.4g. Factors ours / triangles: albedo %.3f, cos %.3f (%.3f vs %.3f), "
        "sun visibility through our stack %.3f (the triangles: 1).\n",
        hits.size(), missed, far, cache / c, model / c, modelUnshadowed / c, tri / c,
        albTri > 0 ? albOurs / albTri : 0.0, cosTri > 0 ? cosOurs / cosTri : 0.0, cosOurs / c,
        cosTri / c, visible / c);
    std::printf("    diagnose:%s", row + 1);
    into.diagnosis += row;
    std::string by =
        "By the cascade our hit lands in: hits, light cache / model at the hit, "
        "black cells where the model is lit:";
    for (std::size_t k = 0; k < nc; ++k) {
      if (countBy[k] == 0) continue;
      char cell[160];
      std::snprintf(cell, sizeof cell, " cascade %zu: %zu, %.3f, %zu;", k, countBy[k],
                    modelBy[k] > 0 ? cacheBy[k] / modelBy[k] : 0.0, darkBy[k]);
      by += cell;
    }
    std::printf("    diagnose: %s\n", by.c_str());
    into.diagnosis += by + "\n";
    char why[700];
    std::snprintf(why, sizeof why,
                  "Black cells where our hit is sunlit through our stack and faces the sun, "
                  "by the light cache's own steps: out of the surface band %zu, the cell's "
                  "normal faces away %zu, shadowed from the cell's surface point with the "
                  "ray starting in a finer cascade %zu / in the cell's own %zu (of which "
                  "lit with 256 / 512 / 1024 shadow steps instead of %u: %zu / %zu / %zu), "
                  "other %zu.\n",
                  blackOutOfBand, blackFacingAway, blackShadowFiner, blackShadowSame,
                  LightCacheSettings{}.maxShadowSteps, blackLitWithMoreSteps[0],
                  blackLitWithMoreSteps[1], blackLitWithMoreSteps[2], blackOther);
    std::printf("    diagnose: %s%s", why, examples.c_str());
    into.diagnosis += why + examples;
  }
}

// Per cage probe, the six axis irradiances from this frame's rays alone (ours and the same
// rays on the triangles, cosine-weighted as the blend weights them) against what the probe
// stores (sampled at its position from its own cascade): the frame's estimate against the
// temporal blend of many such frames.
void ConfigRun::diagnoseFrameAgainstStored(SceneReport& into, const RayComparison& c) {
  const auto& rec = c.rec;
  const auto& f = c.frame;
  const auto& data = c.probeData;
  const auto& cage = c.cage;
  const auto& ours = c.ours;
  const auto& ref = c.ref;
  const std::uint32_t perVolume = cfg_.probes.probesPerVolume(), n = cfg_.probes.raysPerProbe;
  std::vector<gpu_shared::ProbeQuery> q;
  std::vector<double> frameOurs, frameRef;
  for (std::size_t l = 0; l < rec.list.size(); ++l) {
    const std::uint32_t g = rec.list[l];
    const LiveProbe p = probeAt(f, perVolume, g, data[g]);
    if (!cage.count(p.cascade * perVolume + p.cell)) continue;
    for (const glm::vec3& a : kAxes) {
      double so = 0, sr = 0, sw = 0;
      for (std::uint32_t k = 0; k < n; ++k) {
        const std::size_t i = l * n + k;
        const float c = glm::dot(glm::normalize(glm::vec3(rec.directions[i])), a);
        if (c <= 0.0f) continue;
        so += c * ours[i];
        sr += c * ref[i];
        sw += c;
      }
      if (sw <= 0) continue;
      frameOurs.push_back(3.14159265 * so / sw);
      frameRef.push_back(3.14159265 * sr / sw);
      // The probe's own value: at its grid point in its cascade alone, with a view of -a/4
      // that cancels the self-shadow bias (0.2 n + 0.8 view), so trilinear gives it all.
      q.push_back({glm::vec4(p.stack - glm::vec3(data[g]), float(1 + p.cascade)),
                   glm::vec4(a, 0.0f), glm::vec4(-0.25f * a, 0.0f)});
    }
  }
  if (!q.empty()) {
    const std::vector<glm::vec3> stored = gi_.irradiance(q);
    double st = 0, fo = 0, fr = 0;
    for (std::size_t i = 0; i < q.size(); ++i) {
      st += luminance(stored[i]);
      fo += frameOurs[i];
      fr += frameRef[i];
    }
    char row[400];
    std::snprintf(row, sizeof row,
                  "\nThe cage probes' irradiance (6 axis normals, %zu): stored %.4g; from this "
                  "frame's rays alone, ours %.4g and on the triangles %.4g (stored / this "
                  "frame's ours %.3f: the temporal blend; ours / triangles %.3f: the rays).\n",
                  q.size(), st / double(q.size()), fo / double(q.size()), fr / double(q.size()),
                  fo > 0 ? st / fo : 0.0, fr > 0 ? fo / fr : 0.0);
    std::printf("    diagnose:%s", row + 1);
    into.diagnosis += row;
    // By quartile of the stored value: the brightest probes dominate the sums above; a blend
    // biased low where few rays bring the light shows as stored well below this frame's.
    std::vector<std::size_t> idx(q.size());
    for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
    std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
      return luminance(stored[a]) < luminance(stored[b]);
    });
    std::string quart =
        "By quartile of the stored value (darkest first), stored / ours-this-frame / "
        "triangles:";
    for (int qi = 0; qi < 4; ++qi) {
      double a = 0, b = 0, c = 0;
      for (std::size_t j = idx.size() * qi / 4; j < idx.size() * (qi + 1) / 4; ++j) {
        a += luminance(stored[idx[j]]);
        b += frameOurs[idx[j]];
        c += frameRef[idx[j]];
      }
      char cell[120];
      std::snprintf(cell, sizeof cell, " %.3g / %.3g / %.3g;", a, b, c);
      quart += cell;
    }
    std::printf("    diagnose: %s\n", quart.c_str());
    into.diagnosis += quart + "\n";
  }
}

// The comparison's table: mean luminance by what both saw, over every ray, the receivers' cage
// probes' rays and each cascade's probes' rays.
void ConfigRun::writeRayTable(SceneReport& into, const RayComparison& c) {
  const std::size_t rays = c.ours.size();
  const auto& f = c.frame;
  const auto& ours = c.ours;
  const auto& ref = c.ref;
  const auto& group = c.group;
  const auto& inCage = c.inCage;
  const auto& cascadeOf = c.cascadeOf;
  const char* names[RayComparison::kGroups] = {
      "sky in both", "surface in both, sunlit on the triangles",
      "surface in both, unlit on the triangles", "surface in ours only (closed)",
      "surface in Embree's only (leak)"};
  const std::size_t sets = 2 + f.volumes.size();
  std::vector<std::array<double, RayComparison::kGroups>> sumOurs(sets), sumRef(sets);
  std::vector<std::array<std::size_t, RayComparison::kGroups>> count(sets);
  for (std::size_t set = 0; set < sets; ++set) {
    sumOurs[set].fill(0.0);
    sumRef[set].fill(0.0);
    count[set].fill(0);
  }
  for (std::size_t i = 0; i < rays; ++i)
    for (std::size_t set : {std::size_t(0), std::size_t(1), 2 + std::size_t(cascadeOf[i])}) {
      if (set == 1 && !inCage[i]) continue;
      sumOurs[set][group[i]] += ours[i];
      sumRef[set][group[i]] += ref[i];
      ++count[set][group[i]];
    }
  std::string s =
      "\nOne-bounce radiance ray by ray (the bounceGain-0 run, one frame's probe rays): what "
      "each ray brought back against the same ray on the triangles (sky, or emission + "
      "albedo/pi x the delta lights with hard shadows at Embree's hit). Mean luminance; share = "
      "the group's part of the reference's total.\n\n| rays of | what they saw | rays | ours | "
      "reference | ratio | share of reference |\n|---|---|---|---|---|---|---|\n";
  for (std::size_t set = 0; set < sets; ++set) {
    double to = 0, tr = 0;
    std::size_t tc = 0;
    for (int gI = 0; gI < RayComparison::kGroups; ++gI) {
      to += sumOurs[set][gI];
      tr += sumRef[set][gI];
      tc += count[set][gI];
    }
    const std::string name = set == 0   ? "every updated probe"
                             : set == 1 ? "the receivers' cage probes"
                                        : "cascade " + std::to_string(set - 2) + "'s probes";
    const char* label = name.c_str();
    if (tc == 0) continue;
    for (int gI = 0; gI < RayComparison::kGroups; ++gI) {
      if (count[set][gI] == 0) continue;
      char row[300];
      std::snprintf(row, sizeof row, "| %s | %s | %zu | %.4g | %.4g | %.3f | %.1f%% |\n", label,
                    names[gI], count[set][gI], sumOurs[set][gI] / double(count[set][gI]),
                    sumRef[set][gI] / double(count[set][gI]),
                    sumRef[set][gI] > 0 ? sumOurs[set][gI] / sumRef[set][gI] : 0.0,
                    tr > 0 ? 100.0 * sumRef[set][gI] / tr : 0.0);
      s += row;
    }
    char row[200];
    std::snprintf(row, sizeof row, "| %s | all | %zu | %.4g | %.4g | %.3f | 100%% |\n", label, tc,
                  tc ? to / double(tc) : 0.0, tc ? tr / double(tc) : 0.0, tr > 0 ? to / tr : 0.0);
    s += row;
    std::printf("    diagnose: one-bounce ray radiance, %s: ours/Embree %.3f over %zu rays\n",
                label, tr > 0 ? to / tr : 0.0, tc);
  }
  into.diagnosis += s;
}

// --diagnose, on the one-bounce run (bounceGain 0): one frame's probe rays against the same rays
// on the triangles (compareRays), then the sunlit hits taken apart, the cage probes' stored
// irradiance against that frame's, and the table by what both saw.
void ConfigRun::diagnoseRayRadiance(SceneReport& into) {
  const CascadeStackImage img = st_.stack->stackImage();
  const EmbreeScene embree(*sc_.scene.triangles);
  const RayComparison c = compareRays(img, embree);
  diagnoseSunlitHits(into, c, img, embree);
  diagnoseFrameAgainstStored(into, c);
  writeRayTable(into, c);
  diagnoseAwayFromSurfaces(into, true);
}
// --diagnose: the receivers moved off their surface along the normal by one probe spacing of
// their sampling cascade (in free space, up to 4096 of them), GI against the reference there.
// Near the probes-themselves ratio while the receivers' is not: the loss is in sampling next
// to surfaces; as low as the receivers': it is regional, in what the nearby probes gather.
// oneBounce (on the bounceGain-0 run): against the one-bounce reference instead.
void ConfigRun::diagnoseAwayFromSurfaces(SceneReport& into, bool oneBounce) {
  const std::uint32_t depth = oneBounce ? 1u : 64u;
  if (sc_.points.reference.empty()) return;
  const CascadeStackImage img = st_.stack->stackImage();
  const probe::ProbeFieldFrame f = frameConstants(img);
  const std::vector<std::uint32_t> picks = samplingCascades(f.volumes, sc_.queries);
  const std::size_t stride = std::max<std::size_t>(1, sc_.queries.size() / 4096);
  EmbreeScene embree(*sc_.scene.triangles);
  std::vector<gpu_shared::ProbeQuery> moved;
  std::vector<glm::vec3> positions, normals;
  std::vector<std::size_t> source;
  for (std::size_t i = 0; i < sc_.queries.size(); i += stride) {
    const gpu_shared::ProbeQuery& q = sc_.queries[i];
    const glm::vec3 n(q.normal);
    const float spacing = f.volumes[picks[i]].originSpacing.w;  // cascade-0 voxels
    const glm::vec3 at = glm::vec3(q.position) + n * spacing;
    const glm::vec3 world = glm::vec3(img.cascade0MinWorld + glm::dvec3(at) * img.voxelSize0);
    const glm::vec3 from = sc_.points.position[i];
    // Only where the way out is free: the moved point must see its own surface point.
    if (embree.intersect(from + n * float(0.01 * img.voxelSize0), n, 0.0f,
                         float(double(spacing) * img.voxelSize0)))
      continue;
    moved.push_back({glm::vec4(at, 0.0f), q.normal, q.view});
    positions.push_back(world);
    normals.push_back(n);
    source.push_back(i);
  }
  if (moved.empty()) return;
  const std::vector<glm::vec3> e = gi_.irradiance(moved);
  const std::vector<glm::vec3> ref = referenceAt(positions, normals, depth);
  // Perfect probes: the reference at the 8 grid corners of each moved receiver's cage (up to
  // 1024 receivers), with its normal, interpolated trilinearly. Near the reference there: the
  // probe grid can represent the field at the receivers, and any loss is in the probes' values.
  const std::vector<std::uint32_t> picks2 = samplingCascades(f.volumes, moved);
  const std::size_t m = std::min<std::size_t>(moved.size(), 1024);
  std::vector<glm::vec3> cornerAt, cornerNormal, alpha;
  std::vector<gpu_shared::ProbeQuery> cornerQuery;
  std::vector<std::uint32_t> cornerProbe;
  for (std::size_t k = 0; k < m; ++k) {
    const gpu_shared::ProbeVolume& v = f.volumes[picks2[k]];
    const glm::vec3 g =
        (glm::vec3(moved[k].position) - glm::vec3(v.originSpacing)) / v.originSpacing.w;
    const glm::vec3 base = glm::floor(g);
    alpha.push_back(g - base);
    for (std::uint32_t corner = 0; corner < 8; ++corner) {
      const glm::vec3 lc = base + glm::vec3(corner & 1u, corner >> 1 & 1u, corner >> 2 & 1u);
      const glm::vec3 st = glm::vec3(v.originSpacing) + lc * v.originSpacing.w;
      cornerAt.push_back(glm::vec3(img.cascade0MinWorld + glm::dvec3(st) * img.voxelSize0));
      cornerNormal.push_back(normals[k]);
      // The probe's own value: a query at its grid point in its cascade alone, with a view of
      // -n/4 that cancels the self-shadow bias (0.2 n + 0.8 view), so trilinear gives it all.
      cornerQuery.push_back({glm::vec4(st, float(1 + picks2[k])), glm::vec4(normals[k], 0.0f),
                             glm::vec4(-0.25f * normals[k], 0.0f)});
      const glm::ivec3 counts(v.countsRays);
      const glm::ivec3 storage = (glm::ivec3(lc) + glm::ivec3(v.scroll)) % counts;
      cornerProbe.push_back(
          picks2[k] * cfg_.probes.probesPerVolume() +
          std::uint32_t(storage.x + counts.x * (storage.y + counts.y * storage.z)));
    }
  }
  const std::vector<glm::vec3> atCorners = referenceAt(cornerAt, cornerNormal, depth);
  const std::vector<glm::vec3> ourCorners = gi_.irradiance(cornerQuery);
  {  // corner by corner, our probe against the reference at its grid point: moved or not
    const std::vector<glm::vec4> data = gi_.probes().downloadProbeData();
    double o[2] = {}, r[2] = {};
    std::size_t count[2] = {};
    for (std::size_t i = 0; i < ourCorners.size(); ++i) {
      if (luminance(ourCorners[i]) <= 0.0) continue;
      const int moved = glm::length(glm::vec3(data[cornerProbe[i]])) > 0.01f ? 1 : 0;
      o[moved] += luminance(ourCorners[i]);
      r[moved] += luminance(atCorners[i]);
      ++count[moved];
    }
    std::printf(
        "    diagnose: corner probes against the reference at their grid points: in place "
        "%zu, %.3f; relocated %zu, %.3f\n",
        count[0], r[0] > 0 ? o[0] / r[0] : 0.0, count[1], r[1] > 0 ? o[1] / r[1] : 0.0);
  }
  double ideal = 0, refFirst = 0, giFirst = 0, ours = 0;
  std::size_t dark = 0;
  std::vector<glm::vec3> idealAt(m), oursAt(m);
  for (std::size_t k = 0; k < m; ++k) {
    glm::vec3 sum(0.0f), own(0.0f);
    float ownWeight = 0.0f;
    for (std::uint32_t corner = 0; corner < 8; ++corner) {
      const float w = probe::trilinearWeight(alpha[k], corner);
      sum += w * atCorners[k * 8 + corner];
      // A probe that is off (or never updated) reads black: left out, as sampling leaves it.
      if (luminance(ourCorners[k * 8 + corner]) <= 0.0) {
        ++dark;
        continue;
      }
      own += w * ourCorners[k * 8 + corner];
      ownWeight += w;
    }
    idealAt[k] = sum;
    oursAt[k] = ownWeight > 0.0f ? own / ownWeight : glm::vec3(0.0f);
    ours += luminance(oursAt[k]);
    ideal += luminance(sum);
    refFirst += luminance(ref[k]);
    giFirst += luminance(e[k]);
  }
  // The same as errors point by point: perfect probes' relMSE is what the grid's trilinear
  // interpolation alone costs there, whatever the probes hold.
  const std::span<const glm::vec3> refM(ref.data(), m), giM(e.data(), m);
  const double idealRelMse = reference::relMSE(idealAt, refM);
  const double giRelMse = reference::relMSE(giM, refM);
  const double oursRelMse = reference::relMSE(oursAt, refM);
  const std::vector<glm::vec3> atSurface = gi_.irradiance(sc_.queries);
  double giAway = 0, refAway = 0, giHere = 0, refHere = 0;
  for (std::size_t k = 0; k < e.size(); ++k) {
    giAway += luminance(e[k]);
    refAway += luminance(ref[k]);
    giHere += luminance(atSurface[source[k]]);
    refHere += luminance(oneBounce ? sc_.points.referenceOneBounce[source[k]]
                                   : sc_.points.reference[source[k]]);
  }
  char s[900];
  std::snprintf(
      s, sizeof s,
      "\n%sReceivers moved one probe spacing off their surface along the normal (%zu "
      "with a free way out): GI/reference there %.3f; the same receivers on their "
      "surface %.3f. Perfect probes (the reference at the cage corners, "
      "interpolated; %zu receivers): /reference %.3f, and the GI / perfect probes "
      "%.3f; relMSE against the reference there: perfect probes %.4f, the GI %.4f. "
      "Our probes' own values at those corners, interpolated trilinearly with no "
      "visibility (%zu of %zu corners read black, left out): /reference %.3f, relMSE "
      "%.4f.\n",
      oneBounce ? "One bounce (the bounceGain-0 field against the one-bounce reference): " : "",
      e.size(), refAway > 0 ? giAway / refAway : 0.0, refHere > 0 ? giHere / refHere : 0.0, m,
      refFirst > 0 ? ideal / refFirst : 0.0, ideal > 0 ? giFirst / ideal : 0.0, idealRelMse,
      giRelMse, dark, m * 8, refFirst > 0 ? ours / refFirst : 0.0, oursRelMse);
  std::printf("    diagnose:%s", s + 1);
  into.diagnosis += s;
}

// --diagnose: the receivers of each sampling cascade k, sampled from k alone and from each
// coarser cascade alone: whether another cascade's probes would serve them better.
void ConfigRun::diagnoseCascadesAlone(SceneReport& into) {
  const std::vector<glm::vec3>& ref = sc_.points.reference;
  if (ref.empty() || cfg_.cascades < 2) return;
  const CascadeStackImage img = st_.stack->stackImage();
  const probe::ProbeFieldFrame f = frameConstants(img);
  const std::vector<std::uint32_t> picks = samplingCascades(f.volumes, sc_.queries);
  const std::size_t n = f.volumes.size();
  std::vector<std::vector<double>> gi(n, std::vector<double>(n, 0.0));
  std::vector<double> sumRef(n, 0.0);
  for (std::size_t i = 0; i < ref.size(); ++i) sumRef[picks[i]] += luminance(ref[i]);
  for (std::uint32_t c = 0; c < n; ++c) {
    std::vector<gpu_shared::ProbeQuery> q = sc_.queries;
    for (gpu_shared::ProbeQuery& x : q) x.position.w = float(1 + c);
    const std::vector<glm::vec3> e = gi_.irradiance(q);
    for (std::size_t i = 0; i < e.size(); ++i)
      if (picks[i] <= c) gi[picks[i]][c] += luminance(e[i]);
  }
  std::string s =
      "\nReceivers of each sampling cascade sampled from one cascade alone (E/E_ref of that "
      "group; only cascades at least as coarse as the group's):\n\n| sampled from |";
  for (std::size_t c = 0; c < n; ++c) s += " cascade " + std::to_string(c) + " alone |";
  s += "\n|---|";
  for (std::size_t c = 0; c < n; ++c) s += "---|";
  s += "\n";
  for (std::size_t k = 0; k < n; ++k) {
    if (sumRef[k] <= 0.0) continue;
    s += "| " + std::to_string(k) + " |";
    for (std::size_t c = 0; c < n; ++c) {
      char cell[32];
      std::snprintf(cell, sizeof cell, c < k ? " - |" : " %.3f |", gi[k][c] / sumRef[k]);
      s += cell;
    }
    s += "\n";
  }
  std::printf("    diagnose: receivers by cascade, sampled from single cascades:%s", s.c_str());
  into.diagnosis += s;
}

// --diagnose: the field's irradiance at the probes themselves (up to 512 probes that are not
// off, 6 axis normals each) against the reference there: over every probe, and over the
// receivers' cage probes (those the receivers are sampled from; "every probe" is mostly open
// space). Near 1 while the receivers' E/E_ref is not: the loss is in sampling (weights,
// visibility); as low as the receivers': it is in what the probes gather.
void ConfigRun::diagnoseProbeIrradiance(SceneReport& into) {
  const CascadeStackImage img = st_.stack->stackImage();
  const probe::ProbeFieldFrame f = frameConstants(img);
  const std::uint32_t perVolume = cfg_.probes.probesPerVolume();
  const std::vector<LiveProbe> live = liveProbes(gi_, f, perVolume);
  const std::set<std::uint32_t> cage = cageProbes(f, perVolume, sc_.queries);
  std::vector<LiveProbe> inCage;
  for (const LiveProbe& p : live)
    if (cage.count(p.cascade * perVolume + p.cell)) inCage.push_back(p);
  std::string s =
      "\nIrradiance at the probes themselves (sampled at each probe's position, 6 axis "
      "normals, up to 512 probes per set) against the reference there, mean luminance, by the "
      "cascade the probe belongs to (sampling there reads the finest cascade that holds the "
      "point):\n\n| probes | cascade | queries | GI | reference | ratio "
      "|\n|---|---|---|---|---|---|\n";
  // Third set: midway between each cage probe and its +x, +y, +z neighbours (both not off, the
  // segment between them free on the triangles): where trilinear weights mix the two.
  std::vector<LiveProbe> midway;
  {
    EmbreeScene embree(*sc_.scene.triangles);
    std::map<std::uint32_t, glm::vec3> at;
    for (const LiveProbe& p : live) at[p.cascade * perVolume + p.cell] = p.stack;
    for (const LiveProbe& p : inCage) {
      const glm::ivec3 counts(f.volumes[p.cascade].countsRays);
      const glm::ivec3 lc(int(p.cell) % counts.x, int(p.cell) / counts.x % counts.y,
                          int(p.cell) / (counts.x * counts.y));
      for (int a = 0; a < 3; ++a) {
        glm::ivec3 nb = lc;
        ++nb[a];
        if (nb[a] >= counts[a]) continue;
        const auto it = at.find(p.cascade * perVolume +
                                std::uint32_t(nb.x + counts.x * (nb.y + counts.y * nb.z)));
        if (it == at.end()) continue;
        const glm::vec3 w0(img.cascade0MinWorld + glm::dvec3(p.stack) * img.voxelSize0);
        const glm::vec3 w1(img.cascade0MinWorld + glm::dvec3(it->second) * img.voxelSize0);
        const float len = glm::length(w1 - w0);
        if (len <= 0.0f || embree.intersect(w0, (w1 - w0) / len, 0.0f, len)) continue;
        midway.push_back({0.5f * (p.stack + it->second), p.cascade, p.cell});
      }
    }
  }
  for (int set = 0; set < 3; ++set) {
    const std::vector<LiveProbe>& probes = set == 0 ? live : set == 1 ? inCage : midway;
    const std::size_t stride = std::max<std::size_t>(1, probes.size() / 512);
    std::vector<gpu_shared::ProbeQuery> queries;
    std::vector<glm::vec3> positions, normals;
    std::vector<std::uint32_t> cascadeOf;
    for (std::size_t i = 0; i < probes.size(); i += stride)
      for (const glm::vec3& n : kAxes) {
        queries.push_back(
            {glm::vec4(probes[i].stack, 0.0f), glm::vec4(n, 0.0f), glm::vec4(n, 0.0f)});
        positions.push_back(
            glm::vec3(img.cascade0MinWorld + glm::dvec3(probes[i].stack) * img.voxelSize0));
        normals.push_back(n);
        cascadeOf.push_back(probes[i].cascade);
      }
    if (queries.empty()) continue;
    const std::vector<glm::vec3> gi = gi_.irradiance(queries);
    const std::vector<glm::vec3> ref = referenceAt(positions, normals);
    std::vector<double> sumGi(f.volumes.size(), 0.0), sumRef(f.volumes.size(), 0.0);
    std::vector<std::size_t> n(f.volumes.size(), 0);
    for (std::size_t i = 0; i < gi.size(); ++i) {
      sumGi[cascadeOf[i]] += luminance(gi[i]);
      sumRef[cascadeOf[i]] += luminance(ref[i]);
      ++n[cascadeOf[i]];
    }
    const char* label = set == 0   ? "every probe"
                        : set == 1 ? "the receivers' cage probes"
                                   : "midway between neighbouring cage probes";
    for (std::size_t c = 0; c < n.size(); ++c) {
      if (n[c] == 0) continue;
      char row[200];
      std::snprintf(row, sizeof row, "| %s | %zu | %zu | %.4g | %.4g | %.3f |\n", label, c, n[c],
                    sumGi[c] / double(n[c]), sumRef[c] / double(n[c]),
                    sumRef[c] > 0.0 ? sumGi[c] / sumRef[c] : 0.0);
      s += row;
      std::printf("    diagnose: %s of cascade %zu: GI/reference %.3f (%zu queries)\n", label, c,
                  sumRef[c] > 0.0 ? sumGi[c] / sumRef[c] : 0.0, n[c]);
    }
  }
  into.diagnosis += s;
}

}  // namespace sdfstream::bench
