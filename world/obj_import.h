// Minimal Wavefront OBJ import (positions and faces only; materials become the default grey).
// Exists so the demo can place Debian's glmark2-data bunny without a conversion tool.
// Safe on untrusted input: every index is checked, every number must be finite.
#pragma once

#include <filesystem>

#include "world/triangle_scene.h"

namespace sdfstream {

// Throws InputError (Io, Malformed, OutOfRange, NonFinite, Empty) naming the file and line.
TriangleScene loadObj(const std::filesystem::path& path);

}  // namespace sdfstream
