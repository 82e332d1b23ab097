#include "bench/bench_gi_points.h"

#include <algorithm>
#include <cmath>

#include "bench/gpu_clock_warmup.h"
#include "demo/frame_image.h"
#include "gi/camera.h"
#include "gi/cpu_tracer.h"
#include "gi/gpu_stack_tracer.h"
#include "reference/metrics.h"

namespace fs = std::filesystem;

namespace sdfstream::bench {

ViewPoints visiblePoints(const BenchScene& scene, const reference::PathTracer& tracer,
                         const EmbreeScene& embree, int width, int height) {
  ViewPoints v;
  v.width = width;
  v.height = height;
  v.cameras = scene.views;
  v.names = scene.viewNames;
  for (const auto& cam : scene.views) {
    v.start.push_back(v.position.size());
    const auto pts = tracer.visiblePoints(cam, width, height);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (!pts[i].hit) continue;
      // The albedo where the camera ray lands (same triangle the path tracer found).
      const glm::vec3 d = glm::normalize(pts[i].position - cam.position);
      const auto hit = embree.intersect(cam.position, d, 0.0f, 1e30f);
      glm::vec3 a(0.0f);
      if (hit)
        a = glm::clamp(glm::vec3(sampleAlbedo(*scene.triangles, hit->triangle, hit->bary)), 0.0f,
                       1.0f);
      v.position.push_back(pts[i].position);
      v.normal.push_back(pts[i].normal);
      v.albedo.push_back(a);
      v.pixel.push_back(int(i));
    }
  }
  v.start.push_back(v.position.size());
  return v;
}

namespace {

// The scene's stream camera along its view direction, 60° vertical field of view: inside every
// cascade of the stack streamed around it.
Camera streamViewCamera(const BenchScene& scene) {
  Camera cam;
  cam.position = scene.streamCamera;
  cam.target = scene.streamCamera + glm::dvec3(scene.viewDirection);
  cam.fovYDegrees = 60.0;
  return cam;
}

// Steps per ray, and the steps of the longest ray in each group of 32 (see PrimaryTraceTiming).
void countSteps(std::span<const gpu_shared::TraceHit> hits, int width, int height,
                PrimaryTraceTiming& t) {
  if (hits.empty()) return;
  std::vector<std::uint32_t> steps(hits.size());
  for (std::size_t i = 0; i < hits.size(); ++i) steps[i] = hits[i].steps;
  double sum = 0.0, rows = 0.0, tiles = 0.0;
  for (std::size_t i = 0; i < steps.size(); ++i) sum += steps[i];
  for (std::size_t g = 0; g < steps.size(); g += 32) {
    const std::size_t end = std::min(steps.size(), g + 32);
    rows += double(*std::max_element(steps.begin() + std::ptrdiff_t(g),
                                     steps.begin() + std::ptrdiff_t(end))) *
            double(end - g);
  }
  for (int ty = 0; ty < height; ty += 4)
    for (int tx = 0; tx < width; tx += 8) {
      std::uint32_t most = 0;
      int n = 0;
      for (int y = ty; y < std::min(height, ty + 4); ++y)
        for (int x = tx; x < std::min(width, tx + 8); ++x, ++n)
          most = std::max(most, steps[std::size_t(y) * std::size_t(width) + std::size_t(x)]);
      tiles += double(most) * n;
    }
  const double n = double(steps.size());
  t.meanSteps = sum / n;
  t.groupStepsRows = rows / n;
  t.groupStepsTiles = tiles / n;
  std::nth_element(steps.begin(), steps.begin() + std::ptrdiff_t(steps.size() * 99 / 100),
                   steps.end());
  t.p99Steps = steps[steps.size() * 99 / 100];
}

}  // namespace

ViewPoints sdfVisiblePoints(gpu::Context& ctx, const BenchScene& scene, const CascadeStack& stack,
                            std::span<const std::uint32_t> slots, int width, int height) {
  ViewPoints v;
  v.width = width;
  v.height = height;
  v.names = {"player"};
  GpuStackTracer tracer(ctx, stack);
  tracer.sync(stack, slots);
  const CascadeStackImage img = stack.stackImage();
  const Camera cam = streamViewCamera(scene);
  const auto rays = primaryRaysFrom(cam, width, height, img.toStack(cam.position));
  const auto hits = tracer.trace(rays, TraceSettings{});
  v.start.push_back(0);
  for (std::size_t i = 0; i < hits.size(); ++i) {
    if (!(hits[i].flags & gpu_shared::kHitFlagHit)) continue;
    const glm::vec3 p =
        glm::vec3(rays[i].originTMin) + glm::vec3(rays[i].dirTMax) * hits[i].normalT.w;
    v.position.push_back(glm::vec3(img.cascade0MinWorld + glm::dvec3(p) * img.voxelSize0));
    v.normal.push_back(glm::normalize(glm::vec3(hits[i].normalT)));
    v.albedo.push_back(glm::vec3(0.5f));
    v.pixel.push_back(int(i));
  }
  v.start.push_back(v.position.size());
  reference::PinholeCamera pc;
  pc.position = glm::vec3(cam.position);
  pc.forward = scene.viewDirection;
  v.cameras.push_back(pc);
  return v;
}

std::vector<gpu_shared::TraceRay> streamCameraRays(const BenchScene& scene,
                                                   const CascadeStack& stack, int width,
                                                   int height) {
  const CascadeStackImage img = stack.stackImage();
  const Camera cam = streamViewCamera(scene);
  return primaryRaysFrom(cam, width, height, img.toStack(cam.position));
}

PrimaryTraceTiming primaryTraceTiming(gpu::Context& ctx, const BenchScene& scene,
                                      const CascadeStack& stack,
                                      std::span<const std::uint32_t> slots, int width, int height) {
  GpuStackTracer tracer(ctx, stack);
  tracer.sync(stack, slots);
  const CascadeStackImage img = stack.stackImage();
  const auto rays = streamCameraRays(scene, stack, width, height);
  PrimaryTraceTiming t;
  t.rays = rays.size();
  // The warm-up counts the hits and steps, and checks them against the CPU reference.
  const auto hits = tracer.trace(rays, TraceSettings{});
  for (const auto& h : hits) t.hits += (h.flags & gpu_shared::kHitFlagHit) ? 1 : 0;
  countSteps(hits, width, height, t);
  TraceStepKinds kinds;
  const auto cpu = traceStackCpu(img, rays, TraceSettings{}, &kinds);
  t.cpuStepsEqual = cpu.size() == hits.size();
  for (std::size_t r = 0; r < cpu.size() && t.cpuStepsEqual; ++r)
    t.cpuStepsEqual = cpu[r].steps == hits[r].steps;
  for (std::size_t k = 0; k < kinds.steps.size(); ++k)
    t.stepsByKind[k] = double(kinds.steps[k]) / double(std::max<std::size_t>(1, rays.size()));
  // Timed once the clocks are up (bench/gpu_clock_warmup.h): the CPU reference above leaves the
  // GPU idle for seconds. The timing is the warm-up's last batch, dispatches back to back.
  GpuClockWarmup warmup(tracer, rays);
  const GpuClockWarmup::Result w = warmup.run();
  const std::vector<double>& ms = warmup.lastBatch();
  if (!ms.empty() && w.lastMs > 0.0) {
    t.milliseconds = w.lastMs;  // the last batch's median
    const auto [lo, hi] = std::minmax_element(ms.begin(), ms.end());
    t.minMilliseconds = *lo;
    t.maxMilliseconds = *hi;
    t.timedDispatches = std::uint32_t(ms.size());
    t.coldMilliseconds = w.firstMs;
    t.warmupSeconds = w.seconds;
    t.settled = w.settled;
  }
  return t;
}

std::vector<glm::vec3> shadedImage(const ViewPoints& v, std::size_t k,
                                   std::span<const glm::vec3> e) {
  std::vector<glm::vec3> img(std::size_t(v.width * v.height), glm::vec3(0.0f));
  for (std::size_t i = v.start[k]; i < v.start[k + 1]; ++i)
    img[std::size_t(v.pixel[i])] = v.albedo[i] / 3.14159265f * e[i];
  return img;
}

void writeToneMappedPng(const fs::path& path, const std::vector<glm::vec3>& radiance, int w, int h,
                        float exposure) {
  Image8 out;
  out.width = w;
  out.height = h;
  out.rgb.resize(std::size_t(w * h) * 3);
  for (std::size_t i = 0; i < radiance.size(); ++i) {
    const glm::vec3 s = reference::linearToSrgb(reference::toneMapAces(radiance[i], exposure));
    for (int c = 0; c < 3; ++c) out.rgb[i * 3 + c] = std::uint8_t(std::lround(255.0f * s[c]));
  }
  writePng(path, out);
}

}  // namespace sdfstream::bench
