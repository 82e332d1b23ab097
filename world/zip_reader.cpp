#include "world/zip_reader.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>

#include <stb/stb_image.h>  // stbi_zlib_decode_noheader_malloc: raw deflate

#include "core/error.h"
#include "core/printable.h"

namespace sdfstream {
namespace {

using Kind = InputErrorKind;

std::uint32_t le(const std::uint8_t* p, int bytes) {
  std::uint32_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

std::uint64_t fileSize(std::ifstream& in) {
  in.clear();
  in.seekg(0, std::ios::end);
  return std::uint64_t(in.tellg());
}

// n bytes at offset; the range is checked against the file before anything is allocated.
std::vector<std::uint8_t> readAt(std::ifstream& in, const std::string& file, std::uint64_t offset,
                                 std::size_t n) {
  if (offset > fileSize(in) || n > fileSize(in) - offset)
    throw InputError(Kind::Truncated, file, "ends before offset " + std::to_string(offset + n));
  std::vector<std::uint8_t> bytes(n);
  in.clear();
  in.seekg(std::streamoff(offset));
  in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(n));
  if (std::size_t(in.gcount()) != n)
    throw InputError(Kind::Truncated, file, "ends before offset " + std::to_string(offset + n));
  return bytes;
}

std::ifstream open(const std::filesystem::path& zip) {
  std::ifstream in(zip, std::ios::binary);
  if (!in)
    throw InputError(Kind::Io, zip.string(), std::string("cannot open: ") + std::strerror(errno));
  return in;
}

}  // namespace

std::vector<ZipMember> listZip(const std::filesystem::path& zip) {
  const std::string file = zip.string();
  std::ifstream in = open(zip);
  const std::uint64_t size = fileSize(in);
  // The end-of-central-directory record is 22 bytes plus a comment of at most 65535.
  const std::size_t tail = std::size_t(std::min<std::uint64_t>(size, 22 + 65535));
  const std::vector<std::uint8_t> end = readAt(in, file, size - tail, tail);
  std::ptrdiff_t eocd = -1;
  for (std::ptrdiff_t i = std::ptrdiff_t(tail) - 22; i >= 0; --i)
    if (le(&end[std::size_t(i)], 4) == 0x06054b50u) {
      eocd = i;
      break;
    }
  if (eocd < 0) throw InputError(Kind::Malformed, file, "not a zip archive (no end record)");
  const std::uint8_t* e = &end[std::size_t(eocd)];
  const std::uint32_t count = le(e + 10, 2), cdSize = le(e + 12, 4), cdOffset = le(e + 16, 4);
  if (std::uint64_t(cdOffset) + cdSize > size)
    throw InputError(Kind::Truncated, file, "central directory past the end of the file");
  const std::vector<std::uint8_t> cd = readAt(in, file, cdOffset, cdSize);
  std::vector<ZipMember> members;
  std::size_t at = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (at + 46 > cd.size() || le(&cd[at], 4) != 0x02014b50u)
      throw InputError(Kind::Malformed, file, "bad central directory entry " + std::to_string(i));
    const std::uint8_t* c = &cd[at];
    const std::size_t nameLen = le(c + 28, 2), extra = le(c + 30, 2), comment = le(c + 32, 2);
    if (at + 46 + nameLen > cd.size())
      throw InputError(Kind::Malformed, file, "bad central directory entry " + std::to_string(i));
    ZipMember m;
    m.method = std::uint16_t(le(c + 10, 2));
    m.compressedSize = le(c + 20, 4);
    m.size = le(c + 24, 4);
    m.localHeaderOffset = le(c + 42, 4);
    m.name.assign(reinterpret_cast<const char*>(c + 46), nameLen);
    members.push_back(std::move(m));
    at += 46 + nameLen + extra + comment;
  }
  return members;
}

std::vector<std::uint8_t> readZipMember(const std::filesystem::path& zip, const ZipMember& member) {
  // The name comes from the archive: it may hold a newline or be 64 KiB long.
  const std::string file = zip.string() + "!" + printable(member.name);
  if (member.compressedSize > kMaxZipMemberBytes || member.size > kMaxZipMemberBytes)
    throw InputError(Kind::TooLarge, file,
                     "member declares " + std::to_string(std::max(member.compressedSize, member.size)) +
                         " bytes, more than the " + std::to_string(kMaxZipMemberBytes) + " read");
  std::ifstream in = open(zip);
  const std::vector<std::uint8_t> local = readAt(in, file, member.localHeaderOffset, 30);
  if (le(local.data(), 4) != 0x04034b50u)
    throw InputError(Kind::Malformed, file, "bad local header");
  const std::uint64_t data =
      std::uint64_t(member.localHeaderOffset) + 30 + le(&local[26], 2) + le(&local[28], 2);
  std::vector<std::uint8_t> packed = readAt(in, file, data, member.compressedSize);
  if (member.method == 0) return packed;
  if (member.method != 8)
    throw InputError(Kind::Malformed, file,
                     "unsupported compression method " + std::to_string(member.method));
  // stb's Huffman decoder peeks a few bits past the last symbol and reports "bad huffman code"
  // when the stream ends exactly at the buffer's end (Sweet Home 3D's small .mtl members do):
  // zero bytes after the data are never decoded, only peeked at.
  packed.resize(packed.size() + 8, 0);
  // Into a buffer of the declared size (bounded above), so a deflate bomb cannot grow it: stb
  // fails when the data would overrun it. Both sizes fit in int (kMaxZipMemberBytes).
  std::vector<std::uint8_t> bytes(member.size);
  const int got = stbi_zlib_decode_noheader_buffer(
      reinterpret_cast<char*>(bytes.data()), int(bytes.size()),
      reinterpret_cast<const char*>(packed.data()), int(packed.size()));
  if (got < 0 || std::uint32_t(got) != member.size)
    throw InputError(Kind::Malformed, file, "corrupt deflate data");
  return bytes;
}

}  // namespace sdfstream
