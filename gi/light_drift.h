// Whether a change of a scene's lights is a drift (a sun turning a little, a light dimming a
// little), which the probe field follows at its own pace, or a change that wakes every probe.
#pragma once

#include "world/scene_lights.h"

namespace sdfstream {

struct LightDriftLimits {
  float degrees = 1.0f;     // a sun's direction turns by at most this much
  float intensity = 0.05f;  // colour x intensity changes by at most this fraction of itself
};

// True when `now` is `before` with only small changes: the same lights of the same types, every
// sun turned by at most limits.degrees, every light's and the sky's radiance within
// limits.intensity of before (per channel, relative to the larger), and nothing else changed
// (a point or spot light that moves is not a drift). Identical lights are a drift too (of zero).
// limits.degrees <= 0: never a drift.
bool isLightDrift(const SceneLights& before, const SceneLights& now,
                  const LightDriftLimits& limits);

}  // namespace sdfstream
