// Reads single members of a .zip archive (stored or deflated), enough to pull trigger-rally's
// heightmaps and Sweet Home 3D's .sh3f furniture (both zip files) out of their Debian packages.
// No zip64, no encryption. Safe on untrusted input: every offset is checked against the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace sdfstream {

struct ZipMember {
  std::string name;
  std::uint16_t method = 0;  // 0 stored, 8 deflate
  std::uint32_t compressedSize = 0, size = 0, localHeaderOffset = 0;
};

// The central directory. Throws InputError (Io, Malformed, Truncated) naming the archive.
std::vector<ZipMember> listZip(const std::filesystem::path& zip);
// One member's bytes. Throws InputError naming the archive and the member.
std::vector<std::uint8_t> readZipMember(const std::filesystem::path& zip, const ZipMember& member);

}  // namespace sdfstream
