// Daylight at a sun elevation, for a day-to-dusk sweep (`fly --sun-sweep`): the sun keeps its
// azimuth, sinks to the given elevation and is reddened and dimmed by the longer path through
// the air; the sky dims with it. An engine's time-of-day in miniature, not an atmosphere model:
//  - sun: colour × exp(-τ · (m(e) - m(e₀))) per channel, m the Kasten–Young relative air mass
//    (Kasten & Young 1989) and τ = (0.09, 0.15, 0.28) per air mass for red, green and blue
//    (Rayleigh optical depths at ~680/550/440 nm plus a light aerosol load); e₀ is the elevation
//    the sun was given at, so at e₀ nothing changes;
//  - sky: zenith and horizon radiance scaled by (sin e / sin e₀)^0.7, not below 5%, and the
//    horizon tinted towards the sun's new colour as it sets.
#pragma once

#include "world/scene_lights.h"

namespace sdfstream {

// Relative optical air mass at elevation `degrees` above the horizon (1 at the zenith, ~38 at
// the horizon; below it, as at it).
double relativeAirMass(double elevationDegrees);

// `given` with every sun moved to `elevationDegrees` (its azimuth kept) and coloured and dimmed
// as above, the sky dimmed with the first sun; version bumped. A sun pointing straight down has
// no azimuth: it keeps the one of +x. Lights other than suns are unchanged.
SceneLights daylightAt(const SceneLights& given, double elevationDegrees);

// Elevation of a sun whose light travels along `direction` (degrees above the horizon).
double sunElevationDegrees(const glm::vec3& direction);

}  // namespace sdfstream
