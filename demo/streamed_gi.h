// A world pack streamed around a moving camera with the GI core on the streamed stack: the part
// of a frame that `fly` and `view` share. It owns the pack's tile store, the asynchronous tile
// loader, the cascade stack over one shared brick atlas, the GI renderer and the scripted moving
// objects, and it keeps running when the device runs out of memory (the brick atlas, the one
// large buffer whose size is a choice, shrinks instead).
//
// Per frame: stream(camera) (never waits on disk), then withinDeviceMemory(frame, work) around
// giUpdate(camera) and renderFrame(...). Thread safety: one thread, as the gpu::Context.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "demo/gi_shading.h"
#include "demo/moving_objects.h"
#include "demo/render_options.h"
#include "gi/camera.h"
#include "gpu/context.h"
#include "streaming/cascade_stack.h"
#include "streaming/pack_store.h"
#include "streaming/stream_metrics.h"
#include "streaming/tile_loader.h"

namespace sdfstream {

struct StreamedGiOptions {
  std::filesystem::path world;  // a world pack
  int cascades = 6;
  double atlasMiB = 96.0;   // shared brick atlas budget
  double uploadMiB = 16.0;  // brick bytes uploaded per frame at most
  int loaderThreads = 2;
  // The GI settings (kProbeBudgetOfDevice / kRelightBudgetOfDevice resolved by device) and the
  // lights: a pack with lights of its own replaces them unless render.packLights is false.
  RenderOptions render;
  // A mesh scene (glTF/GLB/OBJ/layout JSON, loadTriangles) in the pack's world frame whose
  // triangles are rasterized as the primary surfaces (GiRenderer::setPrimaryMesh); empty: the
  // SDF's, traced. Vulkan only.
  std::filesystem::path primaryMesh;
};

class StreamedGi {
 public:
  // context nullptr: the CPU reference (direct light only, no objects). Throws InputError for a
  // bad pack or an atlas budget the slot index or the device cannot hold; with too little device
  // memory for the budget the atlas holds fewer slots and the stack keeps within them (noted on
  // stderr and in degradedNote()).
  StreamedGi(const StreamedGiOptions& options, gpu::Context* context);
  ~StreamedGi();
  StreamedGi(const StreamedGi&) = delete;
  StreamedGi& operator=(const StreamedGi&) = delete;

  const PackTileStore& store() const { return store_; }
  TileLoader& loader() { return loader_; }
  const TileLoader& loader() const { return loader_; }
  CascadeStack& stack() { return stack_; }
  const CascadeStack& stack() const { return stack_; }
  GiRenderer* renderer() { return renderer_.get(); }
  const GiRenderer* renderer() const { return renderer_.get(); }
  // Lights (change them and bump lights.version), exposure, GI settings as resolved.
  RenderOptions& render() { return render_; }
  const RenderOptions& render() const { return render_; }

  // Turns every sun about the vertical by `degrees` (a light change: the light cache relights
  // within its page budget).
  void turnSuns(double degrees);

  // The rasterized primary's triangles (StreamedGiOptions::primaryMesh), or nullptr.
  const TriangleScene* primaryMesh() const { return primaryMesh_.get(); }

  // Moving objects from the next GI update on (Vulkan only; nullptr: none).
  void setObjects(std::unique_ptr<DemoObjects> objects);
  DemoObjects* objects() { return objects_.get(); }
  const DemoObjects* objects() const { return objects_.get(); }

  // Moves the stack's windows to the camera and takes what the loader finished; never waits.
  StreamFrameStats stream(const Camera& camera);
  // The same with the windows centred on `centre` (a still view from outside the world centres
  // them on what it looks at); viewDirection as CascadeStack::update.
  StreamFrameStats stream(const glm::dvec3& centre, const glm::dvec3& viewDirection);
  // Streams around `centre` until every page the windows need is resident or can never be
  // (atlas full, failed tiles), waiting for the loader: for still views and scripted captures,
  // whose pictures must not depend on how fast the disk was. No GI frames meanwhile. Returns the
  // last frame's stats.
  StreamFrameStats settle(const glm::dvec3& centre, const glm::dvec3& viewDirection);
  // One GI frame on the stack as it stands (relight, probes); empty stats without a device.
  // probesPaused: no probe passes (ProbeFrameInputs::paused), the viewer's GI-off.
  GiFrameStats giUpdate(const Camera& camera, bool probesPaused = false);
  // The camera's view of the stack: direct + indirect light (CPU reference: direct only).
  // `shadeMilliseconds` gets the shading pass's time.
  HdrFrame renderFrame(const Camera& camera, int width, int height,
                       double* shadeMilliseconds = nullptr);

  // Runs the GPU part of a frame. When it runs out of device memory (another process took it,
  // or a pass grew), the brick atlas gives back half its slots and the work runs again: fewer
  // resident bricks (the rest count as atlas-full pages), not a crash. At the atlas's floor the
  // error stands. Test hook: SDFSTREAM_INJECT_DEVICE_OOM_FRAME=F makes frame F's GPU part fail
  // once as an allocation would, so the recovery is tested at a known frame rather than at
  // whichever frame the loader's timing makes a pass grow.
  template <typename Work>
  void withinDeviceMemory(int frame, const Work& work) {
    for (;;) {
      try {
        injectOutOfMemory(frame);
        work();
        return;
      } catch (const gpu::OutOfDeviceMemory& e) {
        shrinkAtlas(frame, e);
      }
    }
  }

  // " Device memory held ..." for a summary when the atlas holds fewer slots than asked for, or
  // "" when it holds them all.
  std::string degradedNote() const;

 private:
  void reserveAtlas();
  void injectOutOfMemory(int frame);
  void shrinkAtlas(int frame, const gpu::OutOfDeviceMemory& error);

  gpu::Context* context_;
  PackTileStore store_;
  RenderOptions render_;
  TileLoader loader_;
  CascadeStack stack_;
  std::unique_ptr<TriangleScene> primaryMesh_;  // declared first: outlives renderer_'s raster
  std::unique_ptr<GiRenderer> renderer_;
  std::unique_ptr<DemoObjects> objects_;
  std::uint64_t giFrame_ = 0;
  std::uint32_t atlasSlotsWanted_ = 0;  // non-zero: the device held fewer slots (reserveAtlas)
  int atlasShrinks_ = 0;                // mid-run shrinks after running out of device memory
  bool reuploadAtlas_ = false;          // the next GI update uploads every slot
  int injectOutOfMemoryFrame_ = -1;     // SDFSTREAM_INJECT_DEVICE_OOM_FRAME
};

}  // namespace sdfstream
