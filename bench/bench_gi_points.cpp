#include "bench/bench_gi_points.h"

#include <algorithm>
#include <cmath>

#include "demo/frame_image.h"
#include "gi/camera.h"
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

PrimaryTraceTiming primaryTraceTiming(gpu::Context& ctx, const BenchScene& scene,
                                      const CascadeStack& stack,
                                      std::span<const std::uint32_t> slots, int width, int height,
                                      int repeats) {
  GpuStackTracer tracer(ctx, stack);
  tracer.sync(stack, slots);
  const CascadeStackImage img = stack.stackImage();
  const Camera cam = streamViewCamera(scene);
  const auto rays = primaryRaysFrom(cam, width, height, img.toStack(cam.position));
  PrimaryTraceTiming t;
  t.rays = rays.size();
  std::vector<double> ms;
  for (int i = 0; i <= repeats; ++i) {
    const auto hits = tracer.trace(rays, TraceSettings{});
    if (i == 0) {  // the warm-up also counts the hits
      for (const auto& h : hits) t.hits += (h.flags & gpu_shared::kHitFlagHit) ? 1 : 0;
      continue;
    }
    ms.push_back(tracer.lastMilliseconds("trace_stack"));
  }
  if (!ms.empty()) {
    std::nth_element(ms.begin(), ms.begin() + std::ptrdiff_t(ms.size() / 2), ms.end());
    t.milliseconds = ms[ms.size() / 2];
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
