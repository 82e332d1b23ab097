// Object SDF settings for tests that want small grids fast: a fixed resolution range (sample
// intervals along the longest axis, objects/object_sdf.h), everything else the default.
#pragma once

#include <cstdint>

#include "objects/object_sdf.h"

namespace sdfstream::test {

inline ObjectSdfSettings objectSdfResolution(
    std::uint32_t maxResolution, std::uint32_t minResolution = ObjectSdfSettings{}.minResolution) {
  ObjectSdfSettings s;
  s.minResolution = minResolution;
  s.maxResolution = maxResolution;
  return s;
}

}  // namespace sdfstream::test
