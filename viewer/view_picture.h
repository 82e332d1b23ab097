// What the viewer shows of a frame: the shaded picture or one of its debug views, scaled to the
// window, with the HUD drawn over it.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "demo/frame_image.h"
#include "demo/gi_shading.h"

namespace sdfstream::viewer {

enum class ViewMode {
  Final,
  Direct,
  Indirect,
  Albedo,
  Normals,
  Cascade,
  Residency,
  ProbeStates,
  ObjectRegions,
  Count
};
static_assert(int(ViewMode::Final) == int(gpu_shared::kFrameFinal) &&
              int(ViewMode::Direct) == int(gpu_shared::kFrameDirect) &&
              int(ViewMode::Indirect) == int(gpu_shared::kFrameIndirect) &&
              int(ViewMode::Albedo) == int(gpu_shared::kFrameAlbedo) &&
              int(ViewMode::Normals) == int(gpu_shared::kFrameNormals) &&
              int(ViewMode::Cascade) == int(gpu_shared::kFrameCascade) &&
              int(ViewMode::Residency) == int(gpu_shared::kFrameResidency) &&
              int(ViewMode::ProbeStates) == int(gpu_shared::kFrameProbeStates) &&
              int(ViewMode::ObjectRegions) == int(gpu_shared::kFrameObjectRegions));
// The Indirect view's extra brightness (as fly's indirect layer).
inline constexpr float kIndirectStops = 2.0f;
std::string_view viewModeName(ViewMode mode);
ViewMode nextViewMode(ViewMode mode);

// The viewer draws its pictures on the GPU (GiRenderer::renderPicture, kFrame* in the same order
// as ViewMode); this is the same picture from a host-side frame, its reference.
// The picture of `mode`: Final (direct + indirect, or direct only when `indirectOn` is false),
// Direct, Indirect (2 stops brighter, as fly's layers) tone-mapped at `exposureStops`; Albedo
// (the hit voxel's sRGB albedo), Normals (n * 0.5 + 0.5), Cascade (the cascade each primary ray
// hit in, one colour each; misses black), Residency (green: hit on streamed bricks of its own
// cascade, orange: sent to a coarser cascade by a page not streamed yet, red: a miss on missing
// data) from the shaded hits. ProbeStates and ObjectRegions need the probe field and the object
// regions on the device: the GPU picture only (black here).
Image8 viewPicture(ViewMode mode, const ShadedView& view, const HdrFrame& frame, bool indirectOn,
                   float exposureStops);

// Nearest-neighbour scaling to width x height (a lower render resolution shown full-window).
Image8 scaleNearest(const Image8& image, int width, int height);

// Lines of text at the top-left over a darkened band, with the project's bitmap font at
// `scale` pixels per font pixel.
void drawHud(Image8& image, const std::vector<std::string>& lines, int scale);

}  // namespace sdfstream::viewer
