// Splotches: how much the GI's irradiance varies over a flat surface compared with how much the
// reference's does there. Over a flat wall lit smoothly, probe-field artefacts (a corner that
// visibility switches on and off, a noisy probe) show as spread the reference does not have, while
// the mean error (relMSE, E/E_ref) can stay small.
#pragma once

#include <cstddef>
#include <span>

#include <glm/glm.hpp>

namespace sdfstream::reference {

struct FlatSpread {
  double gi = -1.0;         // relative standard deviation of the GI's luminance; < 0: no region
  double reference = -1.0;  // the same of the reference's luminance, at the same points
  std::size_t regions = 0;  // views that had a region
  std::size_t points = 0;   // over all regions
};

// Per view (points viewStart[v] .. viewStart[v + 1] - 1), the largest flat region: the points
// whose normal and plane offset n·p agree (normals within about 1°, offsets within
// planeTolerance, in position units), if it holds at least minPoints points. Over each region the
// relative standard deviation (std / mean) of the luminance of `gi` and of `reference`; the
// result pools the regions weighted by their point counts. A ratio gi / reference well above 1
// means splotches. Throws std::invalid_argument when the spans' lengths disagree.
FlatSpread flatRegionSpread(std::span<const glm::vec3> position, std::span<const glm::vec3> normal,
                            std::span<const std::size_t> viewStart, std::span<const glm::vec3> gi,
                            std::span<const glm::vec3> reference, double planeTolerance,
                            std::size_t minPoints = 64);

}  // namespace sdfstream::reference
