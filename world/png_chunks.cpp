#include "world/png_chunks.h"

#include <cstring>

#include "core/error.h"

namespace sdfstream {

bool hasPngSignature(std::istream& in) {
  constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  unsigned char signature[8] = {};
  in.read(reinterpret_cast<char*>(signature), 8);
  return in.gcount() == 8 && std::memcmp(signature, kPngSignature, 8) == 0;
}

void checkPngChunks(std::istream& in, std::uintmax_t fileSize, const std::string& file) {
  std::uintmax_t pos = 8;
  // A whole chunk header is enough for stb to act on its length, even when the CRC is missing.
  while (pos + 8 <= fileSize) {
    unsigned char header[8];
    in.seekg(std::streamoff(pos));
    if (!in.read(reinterpret_cast<char*>(header), 8)) break;
    const std::uint32_t length = std::uint32_t(header[0]) << 24 | std::uint32_t(header[1]) << 16 |
                                 std::uint32_t(header[2]) << 8 | std::uint32_t(header[3]);
    if (fileSize - pos < 12 || length > fileSize - pos - 12)
      throw InputError(InputErrorKind::Truncated, file,
                       "PNG chunk at byte " + std::to_string(pos) + " declares " +
                           std::to_string(length) + " bytes, more than the file holds");
    if (std::memcmp(header + 4, "IEND", 4) == 0) return;
    pos += 12 + std::uintmax_t(length);
  }
  // No IEND: stb decides (a file cut short inside a chunk header is its error to report).
}

}  // namespace sdfstream
