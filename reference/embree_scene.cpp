#include "reference/embree_scene.h"

#include <embree3/rtcore.h>

#include <cstring>
#include <limits>
#include <stdexcept>

namespace sdfstream {

EmbreeScene::EmbreeScene(const TriangleScene& scene) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("Embree: cannot create device");
  scene_ = rtcNewScene(device_);
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                        RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                        scene.positions.size()));
  std::memcpy(v, scene.positions.data(), scene.positions.size() * 3 * sizeof(float));
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0,
                                                             RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                             scene.triangles.size()));
  std::memcpy(idx, scene.triangles.data(), scene.triangles.size() * 3 * sizeof(unsigned));
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  // Watertight edges: without the robust flag a ray can slip between two triangles that share an
  // edge, and the path tracer's closed-box (white furnace) test would leak light.
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  rtcCommitScene(scene_);
}

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

std::optional<EmbreeScene::Hit> EmbreeScene::intersect(const glm::vec3& o, const glm::vec3& d,
                                                       float tMin, float tMax) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = o.x;
  rh.ray.org_y = o.y;
  rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x;
  rh.ray.dir_y = d.y;
  rh.ray.dir_z = d.z;
  rh.ray.tnear = tMin;
  rh.ray.tfar = tMax;
  rh.ray.mask = std::numeric_limits<unsigned>::max();
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  glm::vec3 n(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  float len = glm::length(n);
  return Hit{rh.ray.tfar, len > 0 ? n / len : glm::vec3(0, 1, 0), rh.hit.primID,
             glm::vec2(rh.hit.u, rh.hit.v)};
}

bool EmbreeScene::occluded(const glm::vec3& o, const glm::vec3& d, float tMin, float tMax) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = o.x;
  ray.org_y = o.y;
  ray.org_z = o.z;
  ray.dir_x = d.x;
  ray.dir_y = d.y;
  ray.dir_z = d.z;
  ray.tnear = tMin;
  ray.tfar = tMax;
  ray.mask = std::numeric_limits<unsigned>::max();
  rtcOccluded1(scene_, &context, &ray);
  // Embree marks an occluded ray by setting tfar to -inf.
  return ray.tfar < 0.0f;
}

}  // namespace sdfstream
