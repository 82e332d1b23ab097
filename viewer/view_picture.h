// What the viewer shows of a frame: the shaded picture or one of its debug views, scaled to the
// window, with the HUD drawn over it.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "demo/frame_image.h"
#include "demo/gi_shading.h"

namespace sdfstream::viewer {

enum class ViewMode { Final, Direct, Indirect, Albedo, Normals, Cascade, Count };
std::string_view viewModeName(ViewMode mode);
ViewMode nextViewMode(ViewMode mode);

// The picture of `mode`: Final (direct + indirect, or direct only when `indirectOn` is false),
// Direct, Indirect (2 stops brighter, as fly's layers) tone-mapped at `exposureStops`; Albedo
// (the hit voxel's sRGB albedo), Normals (n * 0.5 + 0.5), Cascade (the cascade each primary ray
// hit in, one colour each; misses black) from the shaded hits.
Image8 viewPicture(ViewMode mode, const ShadedView& view, const HdrFrame& frame, bool indirectOn,
                   float exposureStops);

// Nearest-neighbour scaling to width x height (a lower render resolution shown full-window).
Image8 scaleNearest(const Image8& image, int width, int height);

// Lines of text at the top-left over a darkened band, with the project's bitmap font at
// `scale` pixels per font pixel.
void drawHud(Image8& image, const std::vector<std::string>& lines, int scale);

}  // namespace sdfstream::viewer
