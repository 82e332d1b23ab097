#include "bench/host_objects_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include <memory>

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/task_group.h>

#include "bench/report_format.h"
#include "cards/card_layout.h"
#include "core/atomic_dir.h"
#include "core/stats.h"
#include "gi/card_light_slots.h"
#include "gi/light_cache.h"
#include "gi/object_frame.h"
#include "objects/scripted_motion.h"
#include "shaders/shared/light_layout.h"
#include "shaders/shared/sdf_layout.h"

namespace sdfstream::bench {
namespace {
namespace gs = gpu_shared;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Four cascades of 128 one-metre voxels, nested around the same centre (the world origin at
// 32 m up), every page resident, each with its own toroidal offset: what objectShadowPages and
// the wake bits see in the stress world once it has settled.
CascadeStackImage syntheticStack() {
  CascadeStackImage image;
  image.voxelSize0 = 1.0;
  image.cascade0MinWorld = glm::dvec3(-64.0, -32.0, -64.0);
  for (std::uint32_t c = 0; c < 4; ++c) {
    gs::CascadeTraceParams p{};
    const float scale = float(1u << c);
    p.offsetScale = glm::vec4(glm::vec3(64.0f - 64.0f * scale), scale);
    p.toroidal = glm::uvec4(3u * c + 1u, 5u * c, 7u * c + 2u, c * gs::kCascadePageCount);
    image.params.push_back(p);
  }
  image.pageTables.assign(image.params.size() * gs::kCascadePageCount, gs::kPageResidentBit);
  return image;
}

struct Parts {
  double motion = 0, instances = 0, wake = 0, cards = 0, shadowPages = 0, total = 0;
  double pages = 0, changed = 0;
};

Parts runCount(const HostObjectsOptions& o, std::uint32_t count) {
  const CascadeStackImage image = syntheticStack();
  ObjectLibrary library;
  InstanceSet instances;
  // The stress benchmark's area: 256 x 16 x 256 voxels of cascade 0, on the ground under its
  // centre (which is 32 m above the world origin here, so the ground is at 0).
  const WorldBox area{glm::dvec3(-128.0, 0.0, -128.0), glm::dvec3(128.0, 16.0, 128.0)};
  const ScriptedMotion motion = spreadObjects(instances, library, count, area, o.seed, o.meshes);
  const ObjectSceneSettings settings;
  std::vector<std::uint32_t> meshTexels(library.size()), levelTexels;
  for (std::uint32_t m = 0; m < library.size(); ++m) {
    const ObjectSdf& sdf = library.mesh(m);
    const MeshCards cards =
        layoutCards(sdf.meshMin, sdf.meshMax, std::max(sdf.voxel, float(image.voxelSize0)),
                    settings.cardLayout);
    meshTexels[m] = cards.texelCount;
    levelTexels.insert(levelTexels.end(), cards.lightTexels.begin(), cards.lightTexels.end());
  }
  CardLightLevels levels;
  levels.texels = levelTexels;
  levels.beyond = settings.cardLevelDistance * 64.0f;  // cascade 0's half extent, as ObjectScene
  const glm::vec3 viewer(64.0f);
  gs::GpuLight sun{};
  sun.positionType = glm::vec4(0.0f, 0.0f, 0.0f, float(gs::kLightSun));
  sun.direction = glm::vec4(glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f)), 0.0f);
  sun.colorIntensity = glm::vec4(1.0f);
  sun.shape.w = 1.0f;  // casts shadows
  const std::vector<gs::GpuLight> lights = {sun};

  ObjectFrameData frame;
  CardLightSlots slots;
  std::vector<double> motionMs, instancesMs, wakeMs, cardsMs, shadowMs, totalMs, pages, changed;
  for (int f = 0; f < o.warmup + o.frames; ++f) {
    const auto frameStart = Clock::now();
    auto t = frameStart;
    motion.apply(instances, f / 60.0);
    const double m = msSince(t);
    // As GiSystem: the shadow pages on a worker thread from the moment the changed boxes are
    // known, while the rest of the frame is built and the card slots are assigned (and, there,
    // the objects' passes recorded).
    double shadow = 0.0;
    std::vector<std::uint32_t> shadowed;
    tbb::task_group alongside;
    buildObjectFrame(library, instances, image, settings, frame, [&] {
      alongside.run([&] {
        const auto own = Clock::now();
        shadowed = objectShadowPages(image, frame.changedBoxes, lights);
        shadow = msSince(own);
      });
    });
    t = Clock::now();
    slots.assign(frame.instances, meshTexels, f == 0, settings.cardRelightBudget,
                 settings.cardLightBudgetBytes / 4, viewer, settings.cardRelightTexelBudget,
                 levels);
    const double cards = msSince(t);
    alongside.wait();
    instances.endFrame();
    const double total = msSince(frameStart);
    if (f < o.warmup) continue;
    motionMs.push_back(m);
    instancesMs.push_back(frame.instancesMs);
    wakeMs.push_back(frame.wakeMs);
    cardsMs.push_back(cards);
    shadowMs.push_back(shadow);
    totalMs.push_back(total);
    pages.push_back(double(shadowed.size()));
    changed.push_back(double(frame.changedBoxes.size()));
  }
  return Parts{median(motionMs), median(instancesMs), median(wakeMs), median(cardsMs),
               median(shadowMs), median(totalMs),     median(pages),  median(changed)};
}

}  // namespace

void runHostObjectsBench(const HostObjectsOptions& o) {
  std::unique_ptr<tbb::global_control> limit;
  if (o.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  std::size_t(o.threads));
  const int threads =
      int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  std::printf("bench host: %d frames after %d per count, %d threads\n", o.frames, o.warmup,
              threads);
  std::vector<Parts> results;
  for (std::uint32_t count : o.objects) {
    const auto start = Clock::now();
    results.push_back(runCount(o, count));
    std::printf("bench host: %u objects: %.3f ms per frame (%.1f s)\n", count, results.back().total,
                msSince(start) / 1000.0);
  }
  std::string csv =
      "objects,frames,threads,motion_ms,instances_ms,wake_ms,cards_ms,shadow_pages_ms,total_ms,"
      "us_per_instance,changed_boxes,pages_marked\n";
  std::string md =
      "# Moving objects: host time per frame, no GPU\n\n"
      "`sdfstream bench host`: the spread objects and scripted motion of `sdfstream stress` "
      "(256 x 16 x 256 m, every object moving), a synthetic stack of 4 cascades (1 m voxels, "
      "every page resident) and a sun. Medians over " +
      std::to_string(o.frames) + " frames after " + std::to_string(o.warmup) + ", on " +
      std::to_string(threads) +
      " threads, in ms: *motion* (ScriptedMotion::apply), *instances* (into stack space, with the "
      "list capacity), *wake* (changed boxes and wake bits), *cards* (CardLightSlots::assign), "
      "*shadow pages* (objectShadowPages); each part is its own time, and as in GiSystem the "
      "instances run beside the wake bits, and the shadow pages beside both and the cards: "
      "*total*, the median of the frames' wall times (InstanceSet::endFrame included), is less "
      "than their sum. "
      "GiSystem also uploads what these build and records the passes (see `sdfstream stress`, "
      "whose host figures include them).\n\n"
      "| objects | motion | instances | wake | cards | shadow pages | total | us / instance | "
      "changed boxes | pages marked |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < results.size(); ++k) {
    const Parts& p = results[k];
    const double n = double(o.objects[k]);
    const double perInstance = n > 0 ? 1000.0 * p.total / n : 0.0;
    csv += std::to_string(o.objects[k]) + "," + std::to_string(o.frames) + "," +
           std::to_string(threads) + "," + format("%.4f", p.motion) + "," +
           format("%.4f", p.instances) + "," + format("%.4f", p.wake) + "," +
           format("%.4f", p.cards) + "," + format("%.4f", p.shadowPages) + "," +
           format("%.4f", p.total) + "," + format("%.4f", perInstance) + "," +
           format("%.0f", p.changed) + "," + format("%.0f", p.pages) + "\n";
    md += "| " + std::to_string(o.objects[k]) + " | " + format("%.3f", p.motion) + " | " +
          format("%.3f", p.instances) + " | " + format("%.3f", p.wake) + " | " +
          format("%.3f", p.cards) + " | " + format("%.3f", p.shadowPages) + " | **" +
          format("%.3f", p.total) + "** | " + format("%.3f", perInstance) + " | " +
          format("%.0f", p.changed) + " | " + format("%.0f", p.pages) + " |\n";
  }
  if (results.size() > 1) {
    md +=
        "\nScaling exponents e of total time ~ objects^e between successive counts (1 = "
        "linear):";
    for (std::size_t k = 1; k < results.size(); ++k) {
      const double e = std::log(results[k].total / results[k - 1].total) /
                       std::log(double(o.objects[k]) / double(o.objects[k - 1]));
      md += (k > 1 ? ", " : " ") + std::to_string(o.objects[k - 1]) + " -> " +
            std::to_string(o.objects[k]) + ": " + format("%.2f", e);
    }
    md += ".\n";
  }
  std::printf("%s", md.c_str());
  AtomicDirectory dir(o.out);
  writeFileAtomically(dir.staging() / "results.csv", csv.data(), csv.size());
  writeFileAtomically(dir.staging() / "summary.md", md.data(), md.size());
  dir.commit();
  std::printf("bench host: wrote %s (summary.md, results.csv)\n", o.out.string().c_str());
}

}  // namespace sdfstream::bench
