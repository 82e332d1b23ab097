#include "demo/streamed_gi.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "core/stopwatch.h"
#include "demo/pack_lights.h"
#include "world/import.h"

namespace sdfstream {
namespace {

// The brick atlas budget must fit the slot index (32 bits) and, on a GPU, the device's memory:
// refused at start-up with both figures, not discovered as an allocation failure mid-flight.
void checkAtlasBudget(double atlasMiB, std::size_t slotBytes, const gpu::Context* context) {
  const double bytes = atlasMiB * double(1 << 20);
  if (!(atlasMiB > 0.0) || bytes / double(slotBytes) > double(UINT32_MAX))
    throw InputError(
        InputErrorKind::Usage, "command line",
        "--atlas-mib " + std::to_string(atlasMiB) + ": expected 0 < MiB <= " +
            std::to_string(std::uint64_t(double(UINT32_MAX) * double(slotBytes)) >> 20));
  if (context && bytes > double(context->deviceLocalBytes())) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "--atlas-mib %.0f: a brick atlas budget of %.0f MiB exceeds the %.0f MiB of "
                  "device-local memory of %s",
                  atlasMiB, atlasMiB, double(context->deviceLocalBytes()) / double(1 << 20),
                  context->deviceName().c_str());
    throw InputError(InputErrorKind::TooLarge, "command line", text);
  }
}

StreamingOptions streamingOptions(const StreamedGiOptions& o, const gpu::Context* context) {
  StreamingOptions so;
  so.cascades = o.cascades;
  const std::size_t slotBytes = 4 * (layout::kBrickDistanceWords + 2 * layout::kBrickMaterialCount);
  checkAtlasBudget(o.atlasMiB, slotBytes, context);
  so.atlasSlots = std::uint32_t(o.atlasMiB * double(1 << 20) / slotBytes);
  so.uploadBytesPerFrame = std::size_t(o.uploadMiB * double(1 << 20));
  return so;
}

LoaderOptions loaderOptions(const StreamedGiOptions& o) {
  LoaderOptions lo;
  lo.threads = o.loaderThreads;
  return lo;
}

RenderOptions renderOptionsFor(const StreamedGiOptions& o, const PackManifest& manifest,
                               const gpu::Context* context) {
  RenderOptions render = o.render;
  useOwnLights(render, manifest.lights, o.world.string());  // the manifest the store already read
  resolveDeviceBudgets(render.renderer.settings, context);
  return render;
}

}  // namespace

StreamedGi::StreamedGi(const StreamedGiOptions& o, gpu::Context* context)
    : context_(context),
      store_(o.world),
      render_(renderOptionsFor(o, store_.manifest(), context)),
      loader_(store_, loaderOptions(o)),
      stack_(store_, loader_, streamingOptions(o, context)) {
  if (const char* v = std::getenv("SDFSTREAM_INJECT_DEVICE_OOM_FRAME"); v && *v)
    injectOutOfMemoryFrame_ = std::atoi(v);
  if (!o.primaryMesh.empty() && !context_)
    throw InputError(InputErrorKind::Usage, o.primaryMesh.string(),
                     "the raster primary needs a Vulkan device");
  if (!context_) return;
  renderer_ = std::make_unique<GiRenderer>(*context_, render_.renderer,
                                           std::uint32_t(stack_.cascadeCount()));
  if (!o.primaryMesh.empty()) {
    primaryMesh_ = std::make_unique<TriangleScene>(loadTriangles(o.primaryMesh));
    renderer_->setPrimaryMesh(primaryMesh_.get());
  }
  reserveAtlas();
}

StreamedGi::~StreamedGi() = default;

void StreamedGi::setObjects(std::unique_ptr<DemoObjects> objects) {
  objects_ = std::move(objects);
  if (renderer_)
    renderer_->setObjects(objects_ ? &objects_->library : nullptr,
                          objects_ ? &objects_->instances : nullptr);
}

void StreamedGi::turnSuns(double degrees) {
  const float a = float(degrees * 3.14159265358979323846 / 180.0);
  const float c = std::cos(a), s = std::sin(a);
  for (SceneLight& l : render_.lights.lights)
    if (l.type == SceneLight::Type::Sun)
      l.direction = glm::vec3(c * l.direction.x + s * l.direction.z, l.direction.y,
                              -s * l.direction.x + c * l.direction.z);
  ++render_.lights.version;
}

StreamFrameStats StreamedGi::stream(const Camera& camera) {
  return stack_.update(camera.position, glm::normalize(camera.target - camera.position));
}

StreamFrameStats StreamedGi::stream(const glm::dvec3& centre, const glm::dvec3& viewDirection) {
  return stack_.update(centre, viewDirection);
}

StreamFrameStats StreamedGi::settle(const glm::dvec3& centre, const glm::dvec3& viewDirection) {
  // Each step uploads at most the per-frame budget, so settling takes several; a stack whose
  // missing pages stop going down with the loader idle (pages it can never hold) stops too.
  constexpr int kStepsWithoutProgress = 8;
  StreamFrameStats s;
  std::uint32_t fewest = UINT32_MAX;
  for (int stalled = 0; stalled < kStepsWithoutProgress;) {
    s = stack_.update(centre, viewDirection);
    if (s.missingPages <= s.atlasFullPages + s.failedPages) break;
    stalled = s.missingPages < fewest ? 0 : stalled + 1;
    fewest = std::min(fewest, s.missingPages);
    loader_.waitIdle();
  }
  return s;
}

// Syncs the atlas slots the stack rewrote, relights, updates the probes.
GiFrameStats StreamedGi::giUpdate(const Camera& camera, bool probesPaused) {
  std::vector<std::uint32_t> dirty = stack_.takeDirtySlots();
  if (!renderer_) return GiFrameStats{};
  if (reuploadAtlas_) {  // the atlas was given back and reserved again: it holds nothing
    dirty.resize(stack_.atlasSlots());
    for (std::uint32_t s = 0; s < stack_.atlasSlots(); ++s) dirty[s] = s;
    reuploadAtlas_ = false;
  }
  probe::ProbeFrameInputs inputs;
  inputs.cameraWorld = camera.position;
  inputs.viewDirection = glm::vec3(glm::normalize(camera.target - camera.position));
  inputs.paused = probesPaused;
  return renderer_->update(stack_, dirty, render_.lights, inputs, giFrame_++);
}

HdrFrame StreamedGi::renderFrame(const Camera& camera, int width, int height,
                                 double* shadeMilliseconds) {
  const CascadeStackImage img = stack_.stackImage();
  if (renderer_) {
    HdrFrame frame = renderer_->render(camera, width, height, img, render_.lights);
    if (shadeMilliseconds) *shadeMilliseconds = renderer_->lastTimes().shadeMilliseconds;
    return frame;
  }
  const auto rays = cameraRays(camera, width, height, img);
  const auto start = std::chrono::steady_clock::now();
  HdrFrame frame =
      composeFrame(shadePrimaryCpu(img, rays, toGpu(render_.lights.lights, img),
                                   toGpu(render_.lights.sky), render_.renderer.shading, {}),
                   width, height, {}, {});
  if (shadeMilliseconds) *shadeMilliseconds = millisecondsSince(start);
  return frame;
}

// The atlas on the device before the first frame: with too little device memory for the
// budget, fewer slots (fewer resident bricks; the rest count as atlas-full pages) instead of
// an allocation failure.
void StreamedGi::reserveAtlas() {
  const std::uint32_t want = stack_.atlasSlots();
  const std::uint32_t got = renderer_->reserveAtlasSlots(want);
  if (got >= want) return;
  stack_.limitAtlasSlots(got);
  atlasSlotsWanted_ = want;
  std::fprintf(stderr,
               "note: the device's memory holds %u of the %u brick atlas slots asked for "
               "(%.1f of %.1f MiB): fewer bricks stay resident, the rest are counted as "
               "atlas-full pages\n",
               got, want, double(stack_.atlasBytes()) / (1 << 20),
               double(want) * double(stack_.atlasBytes()) / double(got) / (1 << 20));
}

void StreamedGi::injectOutOfMemory(int frame) {
  if (frame != injectOutOfMemoryFrame_) return;
  injectOutOfMemoryFrame_ = -1;
  throw gpu::OutOfDeviceMemory("injected by SDFSTREAM_INJECT_DEVICE_OOM_FRAME");
}

void StreamedGi::shrinkAtlas(int frame, const gpu::OutOfDeviceMemory& error) {
  if (!renderer_) throw error;
  const std::uint32_t before = stack_.atlasSlots();
  const std::uint32_t got = renderer_->shrinkAtlasSlots(before / 2);  // throws at the floor
  stack_.limitAtlasSlots(got);
  if (!atlasSlotsWanted_) atlasSlotsWanted_ = before;
  ++atlasShrinks_;
  reuploadAtlas_ = true;
  std::fprintf(stderr,
               "note: frame %d ran out of device memory (%s): the brick atlas keeps %u of its %u "
               "slots (%.1f MiB); fewer bricks stay resident, the rest are counted as atlas-full "
               "pages\n",
               frame, error.what(), got, before, double(stack_.atlasBytes()) / (1 << 20));
}

std::string StreamedGi::degradedNote() const {
  if (!atlasSlotsWanted_) return "";
  std::string note = " Device memory held " + std::to_string(stack_.atlasSlots()) + " of the " +
                     std::to_string(atlasSlotsWanted_) +
                     " atlas slots asked for (fewer resident bricks)";
  if (atlasShrinks_ > 0)
    note += "; the atlas shrank " + std::to_string(atlasShrinks_) +
            (atlasShrinks_ == 1 ? " time" : " times") +
            " mid-run when the device ran out of memory";
  return note + ".";
}

}  // namespace sdfstream
