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
Camera defaultStillCamera(const glm::dvec3& boundsMin, const glm::dvec3& boundsMax, double aspect);

// The default still view of a world pack as loaded: the overview above, unless most of what it
// sees is roof. A roofed interior (Sponza's galleries, a closed box) seen from above shows its
// roof: the overview is traced at 96x54 on the CPU (the stack settled around it) and when more
// than half of its hits are upward-facing surfaces in the top fifth of the bounds, the view moves
// into it: the interiorStillCamera, of eight along the horizontal axes, that sees deepest into
// the bounds.
Camera defaultStillCamera(StreamedGi& world, double aspect);

// A view along `axis` (0 = x, 2 = z) towards +axis (sign +1) or -axis (-1): inside the bounds a
// twelfth of the way in from the end it looks away from, a third of the way up, looking a little
// down with 70 degrees of vertical field of view; or outside, 0.6 of the axis's extent beyond that
// end at half height, looking in with 50 degrees.
Camera interiorStillCamera(const glm::dvec3& boundsMin, const glm::dvec3& boundsMax, int axis,
                           int sign, bool outside);

// Where a still view's cascades are centred (see above).
glm::dvec3 stillViewCentre(const Camera& camera, const glm::dvec3& boundsMin,
                           const glm::dvec3& boundsMax);

// Streams, converges `giFrames` GI frames (at least one, which uploads the stack) and shades
// the view. Without a device (world.renderer() null): direct light from the CPU reference.
ViewResult renderStill(StreamedGi& world, const Camera& camera, int width, int height,
                       int giFrames);

}  // namespace sdfstream
