#include "viewer/viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "demo/fly_path.h"
#include "demo/frame_image.h"
#include "demo/moving_objects.h"
#include "demo/still_view.h"
#include "viewer/fly_camera.h"
#include "viewer/swapchain_presenter.h"
#include "viewer/view_picture.h"
#include "viewer/view_script.h"
#include "viewer/window.h"

namespace sdfstream::viewer {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

constexpr double kDegrees = 3.14159265358979323846 / 180.0;
constexpr double kScriptFrameSeconds = 1.0 / 30.0;  // scripted and headless frames: fixed steps
constexpr double kSunStepDegrees = 5.0;
constexpr float kSunIntensityStep = 1.25f;
constexpr double kSoftwareRenderScale = 0.25;
// On a CPU device the probe update dominates the frame (65,536 rays, fly's budget there: ~1.3 s
// a frame on 2 cores); the viewer keeps an eighth of that so it answers the keys.
constexpr std::uint32_t kSoftwareProbeRays = 8192;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// The first sun of the lights, turned by azimuth/elevation steps (degrees) and scaled.
void adjustSun(SceneLights& lights, double azimuthStep, double elevationStep, float scale) {
  for (SceneLight& l : lights.lights) {
    if (l.type != SceneLight::Type::Sun) continue;
    const glm::dvec3 toSun = -glm::normalize(glm::dvec3(l.direction));
    double elevation = std::asin(std::clamp(toSun.y, -1.0, 1.0)) / kDegrees;
    double azimuth = std::atan2(toSun.x, toSun.z) / kDegrees;
    elevation = std::clamp(elevation + elevationStep, -89.0, 89.0);
    azimuth += azimuthStep;
    const double e = elevation * kDegrees, a = azimuth * kDegrees;
    l.direction = -glm::vec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
    l.intensity *= scale;
    ++lights.version;
    return;
  }
}

std::string sunText(const SceneLights& lights) {
  for (const SceneLight& l : lights.lights) {
    if (l.type != SceneLight::Type::Sun) continue;
    const glm::dvec3 toSun = -glm::normalize(glm::dvec3(l.direction));
    char text[96];
    std::snprintf(text, sizeof text, "sun azimuth %.0f elevation %.0f E %.2f",
                  std::atan2(toSun.x, toSun.z) / kDegrees,
                  std::asin(std::clamp(toSun.y, -1.0, 1.0)) / kDegrees, l.intensity);
    return text;
  }
  return "no sun";
}

class ViewSession {
 public:
  explicit ViewSession(const ViewOptions& o) : o_(o) {
    if (o.script) script_ = readViewScript(*o.script);  // bad scripts fail before a window opens
    if (o.headless) {
      ownContext_ = gpu::Context::create(o.device);
    } else {
      window_ =
          std::make_unique<Window>(o.width, o.height, "sdfstream view " + o.world.world.string());
      presenter_ = std::make_unique<SwapchainPresenter>(*window_, o.device, o.vsync);
    }
    gpu::Context& context = presenter_ ? presenter_->context() : *ownContext_;
    software_ = context.isSoftware();
    renderScale_ = o.renderScale > 0.0 ? o.renderScale : software_ ? kSoftwareRenderScale : 1.0;
    StreamedGiOptions worldOptions = o.world;
    GiSettings& gi = worldOptions.render.renderer.settings;
    if (software_ && gi.probes.rayBudget == kProbeBudgetOfDevice)
      gi.probes.rayBudget = kSoftwareProbeRays;
    world_ = std::make_unique<StreamedGi>(worldOptions, &context);
    const PackManifest& manifest = world_->store().manifest();
    const FlyPath path = defaultFlyPath(manifest.boundsMin, manifest.boundsMax);
    const double diagonal = glm::length(manifest.boundsMax - manifest.boundsMin);
    const double speed = o.speed > 0.0 ? o.speed : std::max(0.5, diagonal / 30.0);
    // The start is render's default view: the whole world in the picture, from above, or from
    // inside a roofed interior.
    boundsMin_ = manifest.boundsMin;
    boundsMax_ = manifest.boundsMax;
    camera_ = std::make_unique<FlyCamera>(
        o.camera ? *o.camera : defaultStillCamera(*world_, double(o.width) / o.height), speed);
    if (o.objects > 0) {
      PackGround ground(world_->store(), manifest.boundsMin.y, manifest.boundsMax.y);
      FlyObjectsSettings os;
      os.count = o.objects;
      os.sBegin = std::min(15.0, path.length());
      os.sEnd = std::min(path.length(), 90.0 + 10.0 * speed);
      world_->setObjects(flyObjects(ground, path, os));
    }
    std::printf("view: %s on %s, %d cascades, rendering at %.0f%% of the %s%s\n",
                o.world.world.c_str(), context.deviceName().c_str(), world_->stack().cascadeCount(),
                renderScale_ * 100.0, o.headless ? "picture size (headless)" : "window",
                software_ ? " (CPU Vulkan device: lower resolution and probe budget)" : "");
  }

  int run() {
    auto last = Clock::now();
    int frame = 0;
    for (;; ++frame) {
      if (o_.frames > 0 && frame >= o_.frames) break;
      if (o_.script && std::size_t(frame) >= script_.size()) break;
      const ScriptFrame* scripted = o_.script ? &script_[frame] : nullptr;
      FrameInput input;
      if (window_) input = window_->poll();  // scripted runs still service the window
      if (scripted) input = scripted->input;
      if (window_ && window_->closeRequested()) break;
      if (input.presses[int(Action::Quit)] > 0) break;
      if (scripted && scripted->camera) camera_->set(*scripted->camera);
      applyPresses(input);

      const auto now = Clock::now();
      const double dt =
          (scripted || !window_) ? kScriptFrameSeconds : std::min(0.1, seconds(now - last));
      frameMilliseconds_ = 0.9 * frameMilliseconds_ + 0.1 * seconds(now - last) * 1e3;
      last = now;
      camera_->update(input, dt);
      const Camera cam = camera_->camera();
      if (scripted && scripted->settle)
        world_->settle(streamCentre(cam), glm::normalize(cam.target - cam.position));
      stream_ = world_->stream(streamCentre(cam), glm::normalize(cam.target - cam.position));
      if (!paused_) simSeconds_ += dt;
      if (DemoObjects* objects = world_->objects()) objects->apply(simSeconds_);

      const glm::ivec2 size = presenter_ ? presenter_->prepare() : glm::ivec2(o_.width, o_.height);
      if (size.x <= 0 || size.y <= 0) continue;  // minimised
      const Image8 picture = render(frame, cam, size);
      Image8 shown;
      const bool capture = (scripted && !scripted->captures.empty()) || screenshots_ > 0;
      if (presenter_) {
        if (!presenter_->present(picture, capture ? &shown : nullptr) && capture)
          std::fprintf(stderr,
                       "note: frame %d was dropped (the swapchain was out of date), "
                       "its capture is not written\n",
                       frame);
      } else if (capture) {
        shown = picture;
      }
      if (!shown.rgb.empty()) writeCaptures(frame, scripted, shown);
      if (o_.record) {
        char name[32];
        std::snprintf(name, sizeof name, "frame-%04d.png", frame);
        fs::create_directories(*o_.record);
        writePng(*o_.record / name, picture);
      }
      if (++framesShown_ == 1) {
        firstShown_ = Clock::now();
      } else {
        const GiFrameTimes& t = world_->renderer()->lastTimes();
        const double ms[6] = {gi_.lightMilliseconds, gi_.probeMilliseconds, gi_.objectMilliseconds,
                              t.shadeMilliseconds,   t.sampleMilliseconds,  t.rasterMilliseconds};
        for (int i = 0; i < 6; ++i) gpuSums_[i] += ms[i];
      }
    }
    // After the first frame, which uploads the stack and builds the passes.
    const double wall = framesShown_ > 1 ? seconds(Clock::now() - firstShown_) : 0.0;
    const int timed = std::max(1, framesShown_ - 1);
    std::printf(
        "view: %d frames shown, %.1f fps after the first (GPU ms a frame: light %.3f, "
        "probes %.3f, objects %.3f, shade %.3f, sample %.3f%s)%s\n",
        framesShown_, wall > 0.0 ? double(framesShown_ - 1) / wall : 0.0, gpuSums_[0] / timed,
        gpuSums_[1] / timed, gpuSums_[2] / timed, gpuSums_[3] / timed, gpuSums_[4] / timed,
        world_->primaryMesh() ? (", raster " + std::to_string(gpuSums_[5] / timed)).c_str() : "",
        world_->degradedNote().c_str());
    return 0;
  }

 private:
  // The cascades follow the camera inside the world; outside it they stay on the world's point
  // nearest the camera, so a view of the world from afar still sees it through the stack.
  glm::dvec3 streamCentre(const Camera& cam) const {
    return glm::clamp(cam.position, boundsMin_, boundsMax_);
  }

  void applyPresses(const FrameInput& input) {
    auto pressed = [&](Action a) { return input.presses[int(a)]; };
    if (pressed(Action::Pause) % 2) paused_ = !paused_;
    if (pressed(Action::ToggleGi) % 2) indirect_ = !indirect_;
    if (pressed(Action::ToggleHud) % 2) hud_ = !hud_;
    for (int i = 0; i < pressed(Action::NextView); ++i) mode_ = nextViewMode(mode_);
    screenshots_ += pressed(Action::Screenshot);
    const double azimuth = kSunStepDegrees * (pressed(Action::SunRight) - pressed(Action::SunLeft));
    const double elevation = kSunStepDegrees * (pressed(Action::SunUp) - pressed(Action::SunDown));
    const float scale = std::pow(kSunIntensityStep,
                                 float(pressed(Action::SunBrighter) - pressed(Action::SunDimmer)));
    if (azimuth != 0.0 || elevation != 0.0 || scale != 1.0f)
      adjustSun(world_->render().lights, azimuth, elevation, scale);
  }

  Image8 render(int frame, const Camera& cam, glm::ivec2 size) {
    const int width = std::max(16, int(std::lround(size.x * renderScale_)));
    const int height = std::max(16, int(std::lround(size.y * renderScale_)));
    // Composed on the GPU: only the picture comes back (GiRenderer::renderPicture).
    PictureSettings settings;
    settings.mode = std::uint32_t(mode_);
    settings.indirect = indirect_;
    settings.exposureStops = world_->render().exposureStops;
    settings.indirectStops = kIndirectStops;
    Image8 rendered;
    GiRenderer& renderer = *world_->renderer();
    world_->withinDeviceMemory(frame, [&] {
      // GI off pauses the probe passes too (their GPU time is the point of turning it off).
      gi_ = world_->giUpdate(cam, !indirect_);
      rendered = renderer.renderPicture(cam, width, height, world_->stack().stackImage(),
                                        world_->render().lights, settings);
    });
    Image8 picture = scaleNearest(rendered, size.x, size.y);
    if (hud_ && o_.hud) drawHud(picture, hudLines(width, height), size.y >= 1000 ? 2 : 1);
    return picture;
  }

  std::vector<std::string> hudLines(int width, int height) const {
    const GiFrameTimes& t = world_->renderer()->lastTimes();
    std::uint64_t resident = 0, required = 0;
    for (const CascadeFrameStats& c : stream_.cascades) {
      resident += c.residentBricks;
      required += c.requiredBricks;
    }
    char line[4][256];
    std::snprintf(line[0], sizeof line[0],
                  "%.1f fps (%.1f ms)  GPU ms: light %.2f  probes %.2f  objects %.2f  shade %.2f  "
                  "sample %.2f  raster %.2f",
                  frameMilliseconds_ > 0.0 ? 1e3 / frameMilliseconds_ : 0.0, frameMilliseconds_,
                  gi_.lightMilliseconds, gi_.probeMilliseconds, gi_.objectMilliseconds,
                  t.shadeMilliseconds, t.sampleMilliseconds, t.rasterMilliseconds);
    std::snprintf(line[1], sizeof line[1],
                  "resident %.1f%% of %llu bricks  %u pages missing  %.2f MiB streamed this frame",
                  required ? 100.0 * double(resident) / double(required) : 100.0,
                  (unsigned long long)required, stream_.missingPages,
                  double(stream_.bytesUploaded) / double(1 << 20));
    std::snprintf(line[2], sizeof line[2],
                  "GI %s: %u probes updated, %u rays  objects %u  view %s%s",
                  indirect_ ? "on" : "off (direct only, probes paused)", gi_.probes.probesUpdated,
                  gi_.probes.raysTraced, gi_.objectInstances,
                  std::string(viewModeName(mode_)).c_str(), paused_ ? "  PAUSED" : "");
    std::snprintf(line[3], sizeof line[3], "%s  speed %.1f m/s  %dx%d",
                  sunText(world_->render().lights).c_str(), camera_->speed(), width, height);
    std::vector<std::string> lines(std::begin(line), std::end(line));
    if (software_) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "CPU Vulkan device: rendering at %.0f%% resolution, %u probe rays a frame",
                    renderScale_ * 100.0, world_->render().renderer.settings.probes.rayBudget);
      lines.emplace_back(text);
    }
    lines.emplace_back("keys: WASD QE move, right mouse look, V view, G GI, H HUD, F12 shot");
    return lines;
  }

  void writeCaptures(int frame, const ScriptFrame* scripted, const Image8& shown) {
    fs::create_directories(o_.out);
    if (scripted)
      for (const std::string& name : scripted->captures) {
        writePng(o_.out / (name + ".png"), shown);
        std::printf("view: frame %d captured to %s\n", frame, (o_.out / (name + ".png")).c_str());
      }
    for (; screenshots_ > 0; --screenshots_) {
      char name[48];
      std::snprintf(name, sizeof name, "screenshot-%04d.png", frame);
      writePng(o_.out / name, shown);
      std::printf("view: screenshot %s\n", (o_.out / name).c_str());
    }
  }

  const ViewOptions& o_;
  std::vector<ScriptFrame> script_;
  // Destroyed in reverse: the world (its GPU buffers) before the device it runs on.
  std::unique_ptr<Window> window_;
  std::unique_ptr<SwapchainPresenter> presenter_;
  std::unique_ptr<gpu::Context> ownContext_;
  std::unique_ptr<StreamedGi> world_;
  std::unique_ptr<FlyCamera> camera_;
  glm::dvec3 boundsMin_{0.0}, boundsMax_{0.0};
  bool software_ = false;
  double renderScale_ = 1.0;
  ViewMode mode_ = ViewMode::Final;
  bool indirect_ = true, hud_ = true, paused_ = false;
  int screenshots_ = 0;
  double simSeconds_ = 0.0, frameMilliseconds_ = 0.0;
  int framesShown_ = 0;
  Clock::time_point firstShown_;
  double gpuSums_[6] = {};  // light, probes, objects, shade, sample, raster: GPU ms after frame 1
  StreamFrameStats stream_;
  GiFrameStats gi_;
};

}  // namespace

int runView(const ViewOptions& options) {
  const std::uint64_t before = gpu::Context::processValidationMessageCount();
  int code = 0;
  {
    ViewSession session(options);
    code = session.run();
  }  // torn down first: leaks are reported at destruction
  const char* env = std::getenv("SDFSTREAM_VALIDATION");
  if (options.device.validation || (env && std::string(env) == "1")) {
    const std::uint64_t messages = gpu::Context::processValidationMessageCount() - before;
    std::printf("view: %llu validation messages\n", (unsigned long long)messages);
    if (messages > 0) code = 1;
  }
  return code;
}

}  // namespace sdfstream::viewer
