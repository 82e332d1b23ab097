#include "core/hash.h"

#include <xxhash.h>

#include <cstdio>

namespace sdfstream {

std::uint64_t checksum64(const void* data, std::size_t size) { return XXH3_64bits(data, size); }

std::string toHex(std::uint64_t value) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(value));
  return buf;
}

}  // namespace sdfstream
