// Resource limits for import, checked against an estimate before any large allocation.
#pragma once

#include <cstddef>

namespace sdfstream {

struct ImportLimits {
  // Peak memory import may use (estimate), bytes. Over it: InputError(TooLarge), naming the
  // voxel size and the estimate, before anything big is allocated.
  std::size_t maxBytes = 8ull << 30;
};

}  // namespace sdfstream
