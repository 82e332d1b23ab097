// Renders views of a World for `sdfstream render` and `sdfstream demo`: places one 128³ cascade
// around the camera's target, turns it into a one-cascade stack, converges the GI probes on it
// (camera fixed) and shades the view with direct + indirect light (demo/gi_shading.h). Without
// a GPU (--cpu) it shades direct light with the CPU reference of the same pass. Moving objects
// (setObjects) are shown on the GPU only.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "demo/frame_image.h"
#include "demo/gi_shading.h"
#include "demo/moving_objects.h"
#include "demo/render_options.h"
#include "gi/camera.h"
#include "gi/cpu_tracer.h"
#include "gi/light_cache.h"
#include "world/world.h"

namespace sdfstream {

struct ViewResult {
  HdrFrame frame;
  Image8 image;          // final: direct + indirect, tone-mapped
  Image8 directImage;    // direct light only (what --gi off shows)
  Image8 indirectImage;  // indirect light only: albedo/π · E_indirect
  std::size_t rays = 0;
  std::size_t hits = 0;
  std::size_t objectHits = 0;             // pixels showing a moving object
  std::size_t nonFinite = 0;              // pixels with NaN/Inf radiance (written black)
  double shadeMilliseconds = 0.0;         // trace + direct light pass (GPU time, or CPU wall time)
  double rasterMilliseconds = 0.0;        // the raster primary's draw (GPU time; 0: SDF primary)
  double sampleMilliseconds = 0.0;        // probe_sample for every hit pixel
  double lightMilliseconds = 0.0;         // light cache passes over this view's GI frames
  std::vector<double> probeMilliseconds;  // probe update GPU time of each GI frame of this view
  std::vector<gpu::PassTiming> probePasses;  // the last GI frame's probe passes
  std::vector<glm::vec3> convergence;  // mean E_indirect over a fixed pixel subset, per GI frame
  int framesToConverge = 0;            // GI frames after which the mean stays within 2% of the last
  std::uint32_t residentBricks = 0;
  std::size_t cascadeBytes = 0;
  // Moving objects over this view's GI frames (zero without): region passes' GPU time, and the
  // last frame's probe rays that searched them and hit one.
  double objectMilliseconds = 0.0;
  std::uint32_t objectRays = 0, objectRayHits = 0;
};

class ViewRenderer {
 public:
  // context == nullptr: direct light with the CPU reference (options.gi must be false).
  ViewRenderer(const World& world, gpu::Context* context, const RenderOptions& options,
               TraceSettings trace = {});
  ~ViewRenderer();
  // Converges the probes (the first view of a cascade window runs options.giFrames GI frames;
  // later views of the same window reuse the converged probes) and shades the view.
  ViewResult render(const Camera& camera, int width, int height);

  // Moving objects for the following views (nullptr: none again), GPU only: the CPU reference
  // has none. From now on every GI frame first moves them to their pose at (GI frames since
  // this call) / 30 s; the next view runs `giFrames` more GI frames than its window has had
  // (at least), so the probes see the objects even where they had converged without; and a
  // view is shaded after its GI frames, with the objects where the last frame left them.
  // `objects` must outlive its use here.
  void setObjects(DemoObjects* objects, int giFrames);

 private:
  const World& world_;
  gpu::Context* context_;
  RenderOptions options_;
  std::optional<CascadeImage> cascade_;
  std::unique_ptr<CascadeStackImage> stack_;  // points into *cascade_
  std::unique_ptr<GiRenderer> gpu_;
  LightCacheCpu cpuLight_;
  int framesOnWindow_ = 0;
  std::uint64_t frame_ = 0;
  DemoObjects* objects_ = nullptr;
  int objectFrame_ = 0;   // GI frames since setObjects (the motion's clock at 30 per second)
  int objectTarget_ = 0;  // framesOnWindow_ the next view must reach because of setObjects
};

// The default view: the whole world from the front-right, slightly above.
Camera defaultCamera(const World& world);

// Frames until convergence: the smallest n such that values n-1 .. end (0-based) all have a
// luminance within `tolerance` (relative) of the last value's. 0 for an empty series.
int framesToConverge(const std::vector<glm::vec3>& series, float tolerance = 0.02f);

}  // namespace sdfstream
