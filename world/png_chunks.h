// A guard for decoding untrusted PNG files with stb_image: stb grows its IDAT buffer to what a
// chunk's length claims before reading it, so a 60-byte file claiming a 2 GiB chunk would
// allocate 2 GiB (found by fuzzing). Used by every reader that hands a PNG of the user's to stb.
#pragma once

#include <cstdint>
#include <istream>
#include <string>

namespace sdfstream {

// True when the stream starts with the PNG signature (the stream is left after it).
bool hasPngSignature(std::istream& in);

// Walks the PNG's chunks (length, type, data, CRC) from just after the signature to IEND: every
// length must fit in the bytes left, else InputError(Truncated) naming `file` and the chunk.
void checkPngChunks(std::istream& in, std::uintmax_t fileSize, const std::string& file);

}  // namespace sdfstream
