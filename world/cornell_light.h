// The Cornell box's ceiling light as a downward spot light below the light quad's centre, of
// on-axis intensity Ke × quad area, with the quad's emission removed: direct light is then a
// delta light the probes do not store (DDGI's split). `bench gi` and its path-traced reference
// use this convention for the scene (hard shadows, sharpness 0), and `demo` shows the same box
// (sharpness 64), so their pictures are comparable.
#pragma once

#include "world/scene_lights.h"
#include "world/triangle_scene.h"

namespace sdfstream {

// Replaces the emissive triangles' emission by the spot light it returns. Throws InputError
// (MissingData, file = s.source) when the scene has no emissive triangle.
SceneLight cornellSpotFromEmitters(TriangleScene& s, float shadowSharpness);

}  // namespace sdfstream
