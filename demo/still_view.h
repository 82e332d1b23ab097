// A still view of a world pack through the whole cascade stack (`sdfstream render`): any world
// can be framed, with the same streaming and GI as the fly-through. The windows are centred on
// the camera when it is inside the world's bounds, else on its target: a view from outside
// looks at the world, and the finest cascade belongs where it looks. Every page the windows
// need is streamed in first (an offline view may wait for the disk), then the GI runs its frames
// with the camera fixed and the view is shaded with direct + indirect light.
#pragma once

#include <glm/glm.hpp>

#include "demo/streamed_gi.h"
#include "demo/view_renderer.h"
#include "gi/camera.h"

namespace sdfstream {

// The default still view of a world: its bounds from above and in front, steep enough to look
// into open courtyards, as close as the picture's aspect (width / height) allows.
Camera defaultStillCamera(const glm::dvec3& boundsMin, const glm::dvec3& boundsMax,
                          double aspect);

// Where a still view's cascades are centred (see above).
glm::dvec3 stillViewCentre(const Camera& camera, const glm::dvec3& boundsMin,
                           const glm::dvec3& boundsMax);

// Streams, converges `giFrames` GI frames (at least one, which uploads the stack) and shades
// the view. Without a device (world.renderer() null): direct light from the CPU reference.
ViewResult renderStill(StreamedGi& world, const Camera& camera, int width, int height,
                       int giFrames);

}  // namespace sdfstream
