// Checksums for on-disk data: xxHash64 (XXH3) from Debian's libxxhash. Fast enough that verifying
// every section on load costs far less than reading it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace sdfstream {

std::uint64_t checksum64(const void* data, std::size_t size);
std::string toHex(std::uint64_t value);

}  // namespace sdfstream
