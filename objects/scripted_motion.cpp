#include "objects/scripted_motion.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/split_mix_rng.h"
#include "objects/primitive_meshes.h"

namespace sdfstream {
namespace {

bool finite(glm::dvec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("ScriptedMotion: ") + what);
}

// Fraction in [0,1) of x / period (x any finite real).
double cycle(double x, double period) {
  const double f = x / period - std::floor(x / period);
  return f < 1.0 ? f : 0.0;
}

}  // namespace

std::size_t ScriptedMotion::add(InstanceId id, Mover mover, glm::quat rotation, glm::vec3 scale) {
  ObjectTransform{glm::dvec3(0.0), rotation, scale}.validate();
  Binding b{id, std::move(mover), rotation, scale, {}};
  if (const Orbit* o = std::get_if<Orbit>(&b.mover)) {
    require(finite(o->centre) && std::isfinite(o->phase), "orbit centre / phase not finite");
    require(std::isfinite(o->radius) && o->radius >= 0, "orbit radius must be finite and >= 0");
    require(std::isfinite(o->period) && o->period > 0, "orbit period must be finite and > 0");
  } else if (const Fall* f = std::get_if<Fall>(&b.mover)) {
    require(finite(f->start) && std::isfinite(f->phase) && std::isfinite(f->spinRate),
            "fall start / phase / spin rate not finite");
    require(std::isfinite(f->floorHeight) && f->floorHeight <= f->start.y,
            "fall floor must be finite and <= start.y");
    require(std::isfinite(f->period) && f->period > 0, "fall period must be finite and > 0");
    require(finite(f->spinAxis) && glm::length(f->spinAxis) > 0, "fall spin axis is zero");
  } else {
    const Path& p = std::get<Path>(b.mover);
    require(p.points.size() >= 2, "path needs at least 2 points");
    require(std::isfinite(p.speed) && std::isfinite(p.phase), "path speed / phase not finite");
    b.pathLength.push_back(0.0);
    for (std::size_t i = 0; i < p.points.size(); ++i) {
      require(finite(p.points[i]), "path point not finite");
      const glm::dvec3 next = p.points[(i + 1) % p.points.size()];
      b.pathLength.push_back(b.pathLength.back() + glm::length(next - p.points[i]));
    }
    require(b.pathLength.back() > 0, "path loop has zero length");
  }
  bindings_.push_back(std::move(b));
  return bindings_.size() - 1;
}

ObjectTransform ScriptedMotion::poseAt(std::size_t binding, double t) const {
  const Binding& b = bindings_.at(binding);
  ObjectTransform pose{glm::dvec3(0.0), b.rotation, b.scale};
  if (const Orbit* o = std::get_if<Orbit>(&b.mover)) {
    const double angle = 2 * std::numbers::pi * cycle(t + o->phase * o->period, o->period);
    // Counter-clockwise from above (+y): x → −z.
    pose.translation = o->centre + o->radius * glm::dvec3(std::cos(angle), 0.0, -std::sin(angle));
  } else if (const Fall* f = std::get_if<Fall>(&b.mover)) {
    const double tau = f->period * cycle(t + f->phase * f->period, f->period);
    pose.translation = f->start;
    pose.translation.y = std::max(f->floorHeight, f->start.y - 0.5 * kGravity * tau * tau);
    const glm::dquat spin = glm::angleAxis(f->spinRate * t, glm::normalize(f->spinAxis));
    const glm::dquat base(b.rotation.w, b.rotation.x, b.rotation.y, b.rotation.z);
    pose.rotation = glm::quat(glm::normalize(spin * base));
  } else {
    const Path& p = std::get<Path>(b.mover);
    const double length = b.pathLength.back();
    const double s = length * cycle(p.speed * t + p.phase * length, length);
    // Segment k runs from pathLength[k] to pathLength[k + 1].
    const auto it = std::upper_bound(b.pathLength.begin(), b.pathLength.end(), s);
    const std::size_t k =
        std::min<std::size_t>(std::size_t(it - b.pathLength.begin()) - 1, p.points.size() - 1);
    const double segment = b.pathLength[k + 1] - b.pathLength[k];
    const double along = segment > 0 ? std::clamp((s - b.pathLength[k]) / segment, 0.0, 1.0) : 0.0;
    pose.translation = glm::mix(p.points[k], p.points[(k + 1) % p.points.size()], along);
  }
  return pose;
}

void ScriptedMotion::apply(InstanceSet& set, double timeSeconds) const {
  // Poses in parallel (each a pure function of t), then the changed ones gathered in binding
  // order and moved as one batch (InstanceSet::move checks and stores them in parallel too). The
  // scratch buffers are kept between calls (no per-frame allocation).
  changed_.resize(bindings_.size());
  poses_.resize(bindings_.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bindings_.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const Instance* instance = set.find(bindings_[i].id);
                        changed_[i] = 0;
                        if (!instance) continue;
                        poses_[i] = poseAt(i, timeSeconds);
                        changed_[i] = poses_[i] != instance->pose ? 1 : 0;
                      }
                    });
  // Where each changed binding lands (an exclusive scan of the flags, serial: a word each), then
  // the copies in parallel.
  std::uint32_t moved = 0;
  for (std::size_t i = 0; i < bindings_.size(); ++i) {
    const bool changed = changed_[i] != 0;
    changed_[i] = changed ? moved + 1 : 0;  // 1 + the pair's index, 0: unchanged
    moved += changed ? 1u : 0u;
  }
  moveIds_.resize(moved);
  movePoses_.resize(moved);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bindings_.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        if (changed_[i] == 0) continue;
                        moveIds_[changed_[i] - 1] = bindings_[i].id;
                        movePoses_[changed_[i] - 1] = poses_[i];
                      }
                    });
  set.move(moveIds_, movePoses_);
}

ScriptedMotion spreadObjects(InstanceSet& set, ObjectLibrary& lib, std::uint32_t count,
                             WorldBox area, std::uint64_t seed, std::uint32_t meshes) {
  if (!finite(area.min) || !finite(area.max) || glm::any(glm::greaterThan(area.min, area.max)))
    throw std::invalid_argument("spreadObjects: area must be finite with min <= max");
  auto primitive = [&](const char* name, auto make) {
    if (std::optional<std::uint32_t> found = lib.find(name)) return *found;
    return lib.add(name, make());
  };
  const std::uint32_t box = primitive(
      "spread:box", [] { return makeBoxMesh(glm::vec3(0.5f), glm::vec4(0.8f, 0.6f, 0.4f, 1.0f)); });
  const std::uint32_t sphere = primitive(
      "spread:sphere", [] { return makeSphereMesh(0.5f, glm::vec4(0.4f, 0.6f, 0.8f, 1.0f)); });
  std::vector<std::uint32_t> meshIds = {sphere, box};  // index: a draw's low bit, as before
  for (std::uint32_t k = 2; k < std::max(meshes, 2u); ++k) {
    // Other proportions (taller, flatter) and colours; still within the unit box.
    const float t = float(k) / float(meshes);
    const glm::vec4 colour(0.3f + 0.6f * t, 0.8f - 0.5f * t, 0.4f + 0.4f * (1.0f - t), 1.0f);
    const std::string name =
        std::string(k % 2 ? "spread:box-" : "spread:sphere-") + std::to_string(k);
    meshIds.push_back(primitive(name.c_str(), [&] {
      TriangleScene m = k % 2 ? makeBoxMesh(glm::vec3(0.5f, 0.2f + 0.3f * t, 0.5f), colour)
                              : makeSphereMesh(0.5f, colour);
      if (k % 2 == 0)
        for (glm::vec3& p : m.positions) p.y *= 0.4f + 0.6f * t;  // an ellipsoid
      return m;
    }));
  }

  const glm::dvec3 size = area.max - area.min;
  // Motion stays small next to the area so objects spread over it rather than crowd an edge.
  const double roomXz = 0.25 * std::min(size.x, size.z);
  SplitMixRng rng{seed};
  ScriptedMotion motion;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint64_t draw = rng.next();
    const std::uint32_t mesh =
        meshIds.size() == 2 ? meshIds[draw & 1 ? 0 : 1] : meshIds[draw % meshIds.size()];
    const double longest = rng.uniform(0.3, 2.0);
    glm::vec3 scale;
    for (int a = 0; a < 3; ++a) scale[a] = float(std::max(0.3, longest * rng.uniform(0.5, 1.0)));
    const glm::quat rotation = rng.rotation();
    // Braces: arguments evaluated left to right, so every compiler draws the same numbers.
    const glm::dvec3 p = area.min + size * glm::dvec3{rng.uniform(), rng.uniform(), rng.uniform()};
    Mover mover;
    switch (rng.next() % 3) {
      case 0:
        mover = Orbit{p, std::min(rng.uniform(0.5, 3.0), roomXz), rng.uniform(4.0, 20.0),
                      rng.uniform()};
        break;
      case 1: {
        // Unit meshes: the bounding radius is half the scaled box diagonal.
        const double floor = area.min.y + 0.5 * glm::length(glm::dvec3(scale));
        glm::dvec3 start = p;
        start.y = std::max(start.y, floor);
        const double drop = std::sqrt(2.0 * (start.y - floor) / kGravity);
        mover = Fall{start,         floor,           drop + rng.uniform(0.5, 2.0),
                     rng.uniform(), rng.direction(), rng.uniform(0.2, 1.0)};
        break;
      }
      default: {
        const double hx = std::min(rng.uniform(1.0, 8.0), roomXz * 2);
        const double hz = std::min(rng.uniform(1.0, 8.0), roomXz * 2);
        const double speed = rng.uniform(2.0, 12.0), phase = rng.uniform();
        if (hx > 0 || hz > 0)
          mover = Path{{p + glm::dvec3(-hx, 0, -hz), p + glm::dvec3(hx, 0, -hz),
                        p + glm::dvec3(hx, 0, hz), p + glm::dvec3(-hx, 0, hz)},
                       speed,
                       phase};
        else  // an area flat in x or z leaves no room for a loop: stand still
          mover = Orbit{p, 0.0, 1.0, 0.0};
      }
    }
    const InstanceId id = set.add(mesh, ObjectTransform{p, rotation, scale});
    const std::size_t binding = motion.add(id, std::move(mover), rotation, scale);
    set.move(id, motion.poseAt(binding, 0.0));
  }
  return motion;
}

}  // namespace sdfstream
