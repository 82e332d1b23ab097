#include "bench/bench_gi_peers.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/HDDA.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <nanovdb/util/Ray.h>
#include <openvdb/math/Ray.h>
#include <openvdb/tools/RayIntersector.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "gi/gpu_stack_tracer.h"
#include "world/level_set_bricks.h"
#include "world/mesh_to_sdf.h"

namespace sdfstream::bench {
namespace {

using Clock = std::chrono::steady_clock;
constexpr float kMiss = -1.0f;

double bestOfMs(int runs, const std::function<void()>& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < runs; ++i) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  return best;
}

// Fills `result` with agreement figures against the Embree hits (t in metres, kMiss = miss).
void compare(PeerResult& r, const std::vector<float>& t, const std::vector<float>& embree,
             double voxel) {
  std::size_t agree = 0;
  std::vector<double> dt;
  r.hits = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const bool a = t[i] >= 0.0f, b = embree[i] >= 0.0f;
    r.hits += a;
    agree += a == b;
    if (a && b) dt.push_back(std::abs(double(t[i]) - double(embree[i])) / voxel);
  }
  r.agreement = t.empty() ? 1.0 : double(agree) / double(t.size());
  if (!dt.empty()) {
    std::sort(dt.begin(), dt.end());
    r.medianAbsDtVoxels = dt[dt.size() / 2];
    r.p90AbsDtVoxels = dt[std::min(dt.size() - 1, dt.size() * 9 / 10)];
  }
}

void report(PeerResult& r, std::size_t rays) {
  r.mraysPerSecond = double(rays) / (r.milliseconds * 1e3);
  std::printf(
      "      peer %-10s %-22s %9.2f ms  %8.2f MRays/s  hits %zu  agree %.4f  "
      "median |dt| %.3f vox\n",
      r.name.c_str(), r.where.c_str(), r.milliseconds, r.mraysPerSecond, r.hits, r.agreement,
      r.medianAbsDtVoxels);
}

}  // namespace

std::vector<PeerResult> runPeers(const PeerInputs& in, const PeerRays& rays) {
  const std::size_t n = rays.origin.size();
  const std::string cpu = "CPU, " + std::to_string(in.threads) + " threads";
  tbb::task_arena arena(in.threads);
  auto parallel = [&](const std::function<void(std::size_t, std::size_t)>& body) {
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, n, 1024),
          [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
    });
  };
  std::vector<PeerResult> out;

  // Embree: the exact hits on the source triangles, and the yardstick of the others.
  std::vector<float> tEmbree(n, kMiss);
  PeerResult embree;
  embree.name = "embree";
  embree.where = cpu;
  embree.milliseconds = bestOfMs(in.runs, [&] {
    parallel([&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const auto hit =
            in.embree->intersect(rays.origin[i], rays.direction[i], 0.0f, rays.tMax[i]);
        tEmbree[i] = hit ? hit->t : kMiss;
      }
    });
  });
  compare(embree, tEmbree, tEmbree, in.voxelSize);
  out.push_back(embree);
  report(out.back(), n);

  // Our traversal on the device (GPU timestamps of the trace pass).
  if (in.context) {
    GpuStackTracer tracer(*in.context, *in.stack);
    tracer.sync(*in.stack, in.allSlots);
    TraceSettings settings;
    settings.maxSteps = in.maxSteps;
    settings.hitEpsilon = in.hitEpsilon;
    std::vector<gpu_shared::TraceHit> hits;
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < in.runs + 1; ++r) {  // the first run warms the pipeline up, not counted
      hits = tracer.trace(rays.stack, settings);
      if (r > 0) best = std::min(best, tracer.lastMilliseconds("trace_stack"));
    }
    std::vector<float> t(n, kMiss);
    for (std::size_t i = 0; i < n; ++i)
      if (hits[i].flags & gpu_shared::kHitFlagHit)
        t[i] = float(double(hits[i].normalT.w) * in.voxelSize);
    PeerResult ours;
    ours.name = "sdfstream";
    ours.where = "GPU: " + in.context->deviceName();
    ours.milliseconds = best;
    compare(ours, t, tEmbree, in.voxelSize);
    out.push_back(ours);
    report(out.back(), n);
  }

  // One level set of the source triangles at LOD 0's voxel and lattice, for both VDB peers.
  const auto buildStart = Clock::now();
  const MeshLevelSet ls =
      meshLevelSet(*in.triangles, isClosedMesh(*in.triangles), in.voxelSize, glm::dvec3(0.0));
  std::printf("      level set for the VDB peers: %zu active voxels, %.1f s\n",
              std::size_t(ls.distance->activeVoxelCount()),
              std::chrono::duration<double>(Clock::now() - buildStart).count());

  {
    using Intersector = openvdb::tools::LevelSetRayIntersector<openvdb::FloatGrid>;
    using RayT = Intersector::RayType;
    const Intersector proto(*ls.distance);
    std::vector<float> t(n, kMiss);
    PeerResult r;
    r.name = "openvdb";
    r.where = cpu;
    r.milliseconds = bestOfMs(in.runs, [&] {
      parallel([&](std::size_t b, std::size_t e) {
        Intersector lsri(proto);  // holds an accessor: one per task
        for (std::size_t i = b; i < e; ++i) {
          const glm::vec3 o = rays.origin[i], d = rays.direction[i];
          openvdb::Vec3R dir(d.x, d.y, d.z);
          dir.normalize();  // unit in double precision, as the intersector asserts
          // OpenVDB's rays need 0 < t0 < t1.
          const RayT ray(openvdb::Vec3R(o.x, o.y, o.z), dir, 1e-9,
                         std::max(double(rays.tMax[i]), 2e-9));
          // Not intersectsWS(ray, time): OpenVDB 10 reads the time there before testing.
          openvdb::Vec3R xyz;
          double time = 0.0;
          t[i] = lsri.intersectsWS(ray, xyz, time) ? float(time) : kMiss;
        }
      });
    });
    compare(r, t, tEmbree, in.voxelSize);
    out.push_back(r);
    report(out.back(), n);
  }

  {
    auto handle = nanovdb::openToNanoVDB(*ls.distance);
    const nanovdb::NanoGrid<float>* grid = handle.grid<float>();
    using RayT = nanovdb::Ray<float>;
    std::vector<float> t(n, kMiss);
    PeerResult r;
    r.name = "nanovdb";
    r.where = cpu;
    const float voxel = float(in.voxelSize);
    r.milliseconds = bestOfMs(in.runs, [&] {
      parallel([&](std::size_t b, std::size_t e) {
        auto acc = grid->getAccessor();
        for (std::size_t i = b; i < e; ++i) {
          const glm::vec3 o = rays.origin[i], d = rays.direction[i];
          const RayT world(nanovdb::Vec3f(o.x, o.y, o.z), nanovdb::Vec3f(d.x, d.y, d.z), 0.0f,
                           rays.tMax[i]);
          RayT index = world.worldToIndexF(*grid);  // unit direction: t in voxels
          nanovdb::Coord ijk;
          float v = 0.0f, ti = 0.0f;
          t[i] = nanovdb::ZeroCrossing(index, acc, ijk, v, ti) ? ti * voxel : kMiss;
        }
      });
    });
    compare(r, t, tEmbree, in.voxelSize);
    out.push_back(r);
    report(out.back(), n);
  }

  return out;
}

}  // namespace sdfstream::bench
