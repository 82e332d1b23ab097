// Reads single members of a .zip archive (stored or deflated), enough to pull trigger-rally's
// heightmaps and Sweet Home 3D's .sh3f furniture (both zip files) out of their Debian packages.
// No zip64, no encryption. Safe on untrusted input: every offset is checked against the file,
// and no member bigger than kMaxZipMemberBytes is read (fuzz/zip_fuzz.cpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace sdfstream {

// The largest member, compressed or not, readZipMember reads: the sizes come from the archive, so
// without a bound one 46-byte directory entry could ask for 4 GiB. Debian's furniture and
// trigger-rally members are at most ~9 MB.
inline constexpr std::uint32_t kMaxZipMemberBytes = 256u << 20;

struct ZipMember {
  std::string name;
  std::uint16_t method = 0;  // 0 stored, 8 deflate
  std::uint32_t compressedSize = 0, size = 0, localHeaderOffset = 0;
};

// The central directory. Throws InputError (Io, Malformed, Truncated) naming the archive.
std::vector<ZipMember> listZip(const std::filesystem::path& zip);
// One member's bytes. Throws InputError naming the archive and the member (its name made
// printable, core/printable.h): Truncated, Malformed, TooLarge (over kMaxZipMemberBytes).
std::vector<std::uint8_t> readZipMember(const std::filesystem::path& zip, const ZipMember& member);

}  // namespace sdfstream
