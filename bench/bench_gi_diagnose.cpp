#include "bench/bench_gi_diagnose.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "demo/frame_image.h"
#include "gi/gpu_stack_tracer.h"
#include "reference/metrics.h"

namespace sdfstream::bench {
namespace {

// Adds one ray (t in metres, negative = escaped) to a row.
void count(RayAgreement& row, std::vector<double>& dt, float ours, float embree, bool backface,
           double voxel) {
  ++row.rays;
  row.backfaces += backface;
  const bool a = ours >= 0.0f, b = embree >= 0.0f;
  row.embreeHits += b;
  if (a && !b) ++row.closed;
  if (!a && b) ++row.leaks;
  if (a && b) {
    const double d = (double(ours) - double(embree)) / voxel;
    if (d < -ProbeRayDiagnosis::kEarlyVoxels) ++row.early;
    if (d > ProbeRayDiagnosis::kEarlyVoxels) ++row.late;
    dt.push_back(std::abs(d));
  }
}

void finish(RayAgreement& row, std::vector<double>& dt) {
  if (dt.empty()) return;
  std::sort(dt.begin(), dt.end());
  row.medianAbsDtVoxels = dt[dt.size() / 2];
  row.p90AbsDtVoxels = dt[std::min(dt.size() - 1, dt.size() * 9 / 10)];
}

std::string percent(std::size_t part, std::size_t whole) {
  char s[32];
  std::snprintf(s, sizeof s, "%.1f%%", whole ? 100.0 * double(part) / double(whole) : 0.0);
  return s;
}

std::string row(const std::string& label, const RayAgreement& r) {
  char s[300];
  std::snprintf(s, sizeof s, "| %s | %zu | %s | %s | %s | %s | %s | %s | %.2f | %.2f |\n",
                label.c_str(), r.rays, percent(r.embreeHits, r.rays).c_str(),
                percent(r.closed, r.rays).c_str(), percent(r.early, r.rays).c_str(),
                percent(r.late, r.rays).c_str(), percent(r.leaks, r.rays).c_str(),
                percent(r.backfaces, r.rays).c_str(), r.medianAbsDtVoxels, r.p90AbsDtVoxels);
  return s;
}

}  // namespace

std::vector<gpu_shared::TraceHit> traceFromCascades(const PeerInputs& in,
                                                    std::span<const gpu_shared::TraceRay> rays,
                                                    std::span<const std::uint32_t> first) {
  std::vector<gpu_shared::TraceHit> out(rays.size());
  std::uint32_t cascades = 0;
  for (std::uint32_t c : first) cascades = std::max(cascades, c + 1);
  GpuStackTracer tracer(*in.context, *in.stack);
  tracer.sync(*in.stack, in.allSlots);
  for (std::uint32_t c = 0; c < cascades; ++c) {
    std::vector<gpu_shared::TraceRay> batch;
    std::vector<std::size_t> index;
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (first[i] == c) {
        batch.push_back(rays[i]);
        index.push_back(i);
      }
    if (batch.empty()) continue;
    TraceSettings settings;
    settings.maxSteps = in.maxSteps;
    settings.hitEpsilon = in.hitEpsilon;
    settings.firstCascade = c;
    const std::vector<gpu_shared::TraceHit> hits = tracer.trace(batch, settings);
    for (std::size_t k = 0; k < hits.size(); ++k) out[index[k]] = hits[k];
  }
  return out;
}

ProbeRayDiagnosis diagnoseProbeRays(const PeerInputs& in, const PeerRays& rays) {
  const std::size_t n = rays.origin.size();
  std::vector<float> tEmbree(n, -1.0f), tOurs(n, -1.0f), aEmbree(n, 0.0f), aOurs(n, 0.0f);
  std::vector<std::uint32_t> endCascade(n, 0);
  std::vector<char> backface(n, 0);
  tbb::task_arena arena(in.threads);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const auto hit =
                in.embree->intersect(rays.origin[i], rays.direction[i], 0.0f, rays.tMax[i]);
            tEmbree[i] = hit ? hit->t : -1.0f;
            if (hit)
              aEmbree[i] =
                  luminance(glm::vec3(sampleAlbedo(*in.triangles, hit->triangle, hit->bary)));
          }
        });
  });
  // Ours as the probes trace: each cascade's rays start in that cascade.
  const std::vector<gpu_shared::TraceHit> hits = traceFromCascades(in, rays.stack, rays.cascade);
  for (std::size_t i = 0; i < n; ++i) {
    endCascade[i] = (hits[i].flags >> gpu_shared::kHitCascadeShift) & 15u;
    if (hits[i].flags & gpu_shared::kHitFlagHit) {
      tOurs[i] = float(double(hits[i].normalT.w) * in.voxelSize);
      backface[i] = glm::dot(glm::vec3(hits[i].normalT), rays.direction[i]) > 0.0f;
      const std::uint32_t a = hits[i].albedo;
      const glm::vec3 srgb(float(a & 255u), float(a >> 8 & 255u), float(a >> 16 & 255u));
      aOurs[i] = luminance(reference::srgbToLinear(srgb / 255.0f));
    }
  }
  std::uint32_t cascades = 0;
  for (std::uint32_t c : rays.cascade) cascades = std::max(cascades, c + 1);
  ProbeRayDiagnosis d;
  std::uint32_t stackCascades = 0;
  for (std::uint32_t c : endCascade) stackCascades = std::max(stackCascades, c + 1);
  d.byCascade.resize(std::max(stackCascades, cascades));
  std::vector<std::vector<double>> dt(d.byCascade.size());
  std::vector<double> dtAll;
  std::size_t skyOurs = 0, skyEmbree = 0;
  for (std::size_t i = 0; i < n; ++i) {
    count(d.byCascade[endCascade[i]], dt[endCascade[i]], tOurs[i], tEmbree[i], backface[i],
          in.voxelSize);
    count(d.all, dtAll, tOurs[i], tEmbree[i], backface[i], in.voxelSize);
    skyOurs += tOurs[i] < 0.0f;
    skyEmbree += tEmbree[i] < 0.0f;
    if (tOurs[i] >= 0.0f && tEmbree[i] >= 0.0f &&
        std::abs(double(tOurs[i]) - double(tEmbree[i])) <=
            ProbeRayDiagnosis::kEarlyVoxels * in.voxelSize) {
      d.albedoOurs += aOurs[i];
      d.albedoEmbree += aEmbree[i];
      ++d.albedoRays;
    }
  }
  if (d.albedoRays) {
    d.albedoOurs /= double(d.albedoRays);
    d.albedoEmbree /= double(d.albedoRays);
  }
  for (std::size_t c = 0; c < d.byCascade.size(); ++c) finish(d.byCascade[c], dt[c]);
  finish(d.all, dtAll);
  d.skyOurs = n ? double(skyOurs) / double(n) : 0.0;
  d.skyEmbree = n ? double(skyEmbree) / double(n) : 0.0;
  return d;
}

SunAgreement diagnoseSunVisibility(const PeerInputs& in, const PeerRays& rays,
                                   const CascadeStackImage& img, glm::vec3 toSun) {
  const std::size_t n = rays.origin.size();
  const std::size_t stride = std::max<std::size_t>(1, n / 1000000);
  struct Point {
    glm::vec3 world, normal;
    bool lit;
  };
  std::vector<Point> points((n + stride - 1) / stride);
  std::vector<char> valid(points.size(), 0);
  tbb::task_arena arena(in.threads);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, points.size(), 1024),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t k = r.begin(); k != r.end(); ++k) {
            const std::size_t i = k * stride;
            const auto hit =
                in.embree->intersect(rays.origin[i], rays.direction[i], 0.0f, rays.tMax[i]);
            if (!hit) continue;
            glm::vec3 nrm = hit->normal;
            if (glm::dot(nrm, rays.direction[i]) > 0.0f) nrm = -nrm;
            if (glm::dot(nrm, toSun) <= 0.0f) continue;
            const glm::vec3 x = rays.origin[i] + rays.direction[i] * hit->t;
            const float eps = float(1e-3 * in.voxelSize);
            points[k] = {x, nrm, !in.embree->occluded(x + nrm * eps, toSun, 0.0f, 1e30f)};
            valid[k] = 1;
          }
        });
  });
  std::vector<gpu_shared::TraceRay> shadow;
  std::vector<std::uint32_t> first;
  std::vector<std::size_t> index;
  const std::uint32_t cascades = std::uint32_t(img.params.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!valid[k]) continue;
    const glm::vec3 p0 = img.toStack(glm::dvec3(points[k].world));
    std::uint32_t c = cascades - 1;
    for (std::uint32_t j = 0; j < cascades; ++j) {
      const glm::vec4 os = img.params[j].offsetScale;
      const glm::vec3 local = (p0 - glm::vec3(os)) / os.w;
      if (glm::all(glm::greaterThanEqual(local, glm::vec3(0.0f))) &&
          glm::all(glm::lessThanEqual(local, glm::vec3(128.0f)))) {
        c = j;
        break;
      }
    }
    // The light cache starts half a voxel off the SDF's surface, which lies half a LOD-0 voxel
    // off an open sheet's triangles (mesh_to_sdf.h) and, in a coarser cascade, about one of its
    // voxels proud (the min-filter chain): from the triangle, one voxel in cascade 0 and two in
    // coarser ones.
    const float voxel = img.params[c].offsetScale.w;
    gpu_shared::TraceRay r;
    r.originTMin = glm::vec4(p0 + points[k].normal * ((c == 0 ? 1.0f : 2.0f) * voxel), 0.0f);
    r.dirTMax = glm::vec4(toSun, 1e9f);
    shadow.push_back(r);
    first.push_back(c);
    index.push_back(k);
  }
  SunAgreement a;
  const std::vector<gpu_shared::TraceHit> hits = traceFromCascades(in, shadow, first);
  for (std::size_t j = 0; j < hits.size(); ++j) {
    // Out of steps counts as blocked, as the light cache counts it.
    const bool oursLit =
        (hits[j].flags & (gpu_shared::kHitFlagHit | gpu_shared::kHitFlagRanOutOfSteps)) == 0u;
    const bool lit = points[index[j]].lit;
    ++a.facing;
    a.sunlit += lit;
    a.lost += lit && !oursLit;
    a.gained += !lit && oursLit;
  }
  return a;
}

std::vector<std::uint32_t> samplingCascades(std::span<const gpu_shared::ProbeVolume> volumes,
                                            std::span<const gpu_shared::ProbeQuery> queries) {
  std::vector<std::uint32_t> out;
  out.reserve(queries.size());
  const std::uint32_t cascades = std::uint32_t(volumes.size());
  for (const gpu_shared::ProbeQuery& q : queries) {
    const glm::vec3 x(q.position);
    std::uint32_t pick = cascades > 0 ? cascades - 1 : 0;
    for (std::uint32_t c = 0; c + 1 < cascades; ++c) {
      const gpu_shared::ProbeVolume& v = volumes[c];
      const glm::vec3 g = (x - glm::vec3(v.originSpacing)) / v.originSpacing.w;
      const glm::vec3 hi = glm::vec3(glm::ivec3(v.countsRays)) - 1.0f - g;
      if (std::min({g.x, g.y, g.z, hi.x, hi.y, hi.z}) > 0.5f) {
        pick = c;
        break;
      }
    }
    out.push_back(pick);
  }
  return out;
}

std::string diagnosisMarkdown(const ProbeRayDiagnosis& d, std::size_t cascades) {
  char early[16];
  std::snprintf(early, sizeof early, "%.0f", ProbeRayDiagnosis::kEarlyVoxels);
  std::string s =
      "Probe rays of one frame, traced as the probes trace them (from the probe's "
      "cascade outwards) and by Embree on the source triangles, by the cascade our ray ends in. "
      "*closed*: we hit where the triangles let the ray escape; *early* / *late*: both hit, ours "
      "more than " +
      std::string(early) +
      " LOD-0 voxels before / after Embree's; *leak*: we escape where the triangles block; "
      "*backface*: we hit a surface whose SDF gradient faces along the ray (the probe sees the "
      "inside of geometry); |Δt| in LOD-0 voxels over rays both hit.\n\n"
      "| ends in cascade | rays | Embree hits | closed | early | late | leak | backface | median "
      "|Δt| | p90 |Δt| |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < d.byCascade.size() && c < std::max<std::size_t>(cascades, 1); ++c)
    s += row(std::to_string(c), d.byCascade[c]);
  s += row("all", d.all);
  char sky[160];
  std::snprintf(
      sky, sizeof sky, "\nRays reaching the sky: ours %.1f%%, Embree %.1f%% (ratio %.3f).\n",
      100.0 * d.skyOurs, 100.0 * d.skyEmbree, d.skyEmbree > 0.0 ? d.skyOurs / d.skyEmbree : 0.0);
  char albedo[200];
  std::snprintf(albedo, sizeof albedo,
                "Albedo where both hit (within %s voxels, %zu rays): ours %.3f, the source's %.3f "
                "(ratio %.3f).\n",
                early, d.albedoRays, d.albedoOurs, d.albedoEmbree,
                d.albedoEmbree > 0.0 ? d.albedoOurs / d.albedoEmbree : 0.0);
  return s + sky + albedo;
}

}  // namespace sdfstream::bench
