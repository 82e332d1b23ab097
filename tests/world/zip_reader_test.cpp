// world/zip_reader.h on archives built byte by byte here: the members' bytes, and what breaks
// fuzz/zip_fuzz.cpp's contract (a name that broke the one-line error, sizes that made the reader
// allocate what the archive asked for; both found reviewing the reader against that contract).
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/test_data.h"
#include "world/zip_reader.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

struct Entry {
  std::string name;
  std::uint16_t method = 0;
  std::vector<std::uint8_t> data;  // as stored (raw deflate for method 8)
  std::uint32_t size = 0;          // declared uncompressed size
  std::uint32_t compressedSize = 0;  // declared; 0 means data.size()
};

void le(std::vector<std::uint8_t>& out, std::uint32_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(std::uint8_t(v >> (8 * i)));
}

// A zip archive with one local header + data per entry, the central directory and its end record
// (CRCs are left 0: the reader does not check them).
fs::path writeZip(const std::string& name, const std::vector<Entry>& entries) {
  std::vector<std::uint8_t> z, cd;
  for (const Entry& e : entries) {
    const std::uint32_t offset = std::uint32_t(z.size());
    const std::uint32_t packed = e.compressedSize ? e.compressedSize : std::uint32_t(e.data.size());
    le(z, 0x04034b50u, 4), le(z, 20, 2), le(z, 0, 2), le(z, e.method, 2), le(z, 0, 4), le(z, 0, 4);
    le(z, packed, 4), le(z, e.size, 4), le(z, std::uint32_t(e.name.size()), 2), le(z, 0, 2);
    z.insert(z.end(), e.name.begin(), e.name.end());
    z.insert(z.end(), e.data.begin(), e.data.end());
    le(cd, 0x02014b50u, 4), le(cd, 20, 2), le(cd, 20, 2), le(cd, 0, 2), le(cd, e.method, 2);
    le(cd, 0, 4), le(cd, 0, 4), le(cd, packed, 4), le(cd, e.size, 4);
    le(cd, std::uint32_t(e.name.size()), 2), le(cd, 0, 2), le(cd, 0, 2), le(cd, 0, 2), le(cd, 0, 2);
    le(cd, 0, 4), le(cd, offset, 4);
    cd.insert(cd.end(), e.name.begin(), e.name.end());
  }
  const std::uint32_t cdOffset = std::uint32_t(z.size());
  z.insert(z.end(), cd.begin(), cd.end());
  le(z, 0x06054b50u, 4), le(z, 0, 2), le(z, 0, 2), le(z, std::uint32_t(entries.size()), 2);
  le(z, std::uint32_t(entries.size()), 2), le(z, std::uint32_t(cd.size()), 4), le(z, cdOffset, 4);
  le(z, 0, 2);
  const fs::path path = test::scratchDir("zip-" + name) / (name + ".zip");
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(z.data()), std::streamsize(z.size()));
  return path;
}

// Raw deflate of `data` as one final stored block (RFC 1951 §3.2.4).
std::vector<std::uint8_t> storedDeflate(const std::vector<std::uint8_t>& data) {
  std::vector<std::uint8_t> out{0x01};
  le(out, std::uint32_t(data.size()), 2);
  le(out, ~std::uint32_t(data.size()) & 0xFFFFu, 2);
  out.insert(out.end(), data.begin(), data.end());
  return out;
}

InputError readError(const fs::path& zip, const ZipMember& m) {
  try {
    readZipMember(zip, m);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "member " << m.name << " was read";
  return InputError(InputErrorKind::Io, "", "");
}

TEST(ZipReader, ReadsStoredAndDeflatedMembers) {
  const std::vector<std::uint8_t> text{'h', 'e', 'l', 'l', 'o'};
  const fs::path zip = writeZip("members", {{"a.txt", 0, text, 5}, {"b.txt", 8, storedDeflate(text), 5}});
  const std::vector<ZipMember> members = listZip(zip);
  ASSERT_EQ(members.size(), 2u);
  EXPECT_EQ(members[1].name, "b.txt");
  EXPECT_EQ(readZipMember(zip, members[0]), text);
  EXPECT_EQ(readZipMember(zip, members[1]), text);
}

// The member's name is part of the error's file name; one holding a newline made
// the error two lines. It is now quoted printable.
TEST(ZipReader, MemberNameWithNewlineKeepsTheErrorOneLine) {
  const fs::path zip = writeZip("name", {{"maps/a\nb.png", 9, {1, 2, 3}, 3}});
  const InputError e = readError(zip, listZip(zip).at(0));
  const std::string what = e.what();
  EXPECT_EQ(e.kind(), InputErrorKind::Malformed) << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  EXPECT_EQ(e.file(), zip.string() + "!maps/a\\x0ab.png");
}

// Over-limit allocation: a directory entry declaring a 4 GiB member made the
// reader allocate 4 GiB before finding the file too short. Now refused before any allocation.
TEST(ZipReader, MemberOverTheSizeLimitIsTooLarge) {
  Entry huge{"huge.bin", 0, {1, 2, 3}, 0xFFFFFF00u, 0xFFFFFF00u};
  const fs::path zip = writeZip("huge", {huge});
  const InputError e = readError(zip, listZip(zip).at(0));
  EXPECT_EQ(e.kind(), InputErrorKind::TooLarge) << e.what();
  EXPECT_NE(std::string(e.what()).find(std::to_string(kMaxZipMemberBytes)), std::string::npos)
      << e.what();
}

// A declared size just under the limit on a short file: Truncated, still before allocating.
TEST(ZipReader, MemberPastTheEndOfTheFileIsTruncated) {
  Entry cut{"cut.bin", 0, {1, 2, 3}, 1000, 1000};
  const fs::path zip = writeZip("cut", {cut});
  EXPECT_EQ(readError(zip, listZip(zip).at(0)).kind(), InputErrorKind::Truncated);
}

// Deflate data that expands beyond the declared size is corrupt; it no longer grows a buffer of
// its own choosing first.
TEST(ZipReader, DeflateLongerThanDeclaredIsMalformed) {
  const std::vector<std::uint8_t> data(4096, 'x');
  const fs::path zip = writeZip("bomb", {{"bomb.bin", 8, storedDeflate(data), 16}});
  EXPECT_EQ(readError(zip, listZip(zip).at(0)).kind(), InputErrorKind::Malformed);
}


// stb's decoder peeks past the last Huffman code and failed ("bad huffman code") on streams that
// end exactly at the buffer's end, as Sweet Home 3D's small .mtl members do.
TEST(ZipReader, ReadsEveryMemberOfSweetHome3dsFurniture) {
  const fs::path archive = "/usr/share/sweethome3d/furniture/BlendSwap-CC-0.sh3f";
  if (!fs::exists(archive))
    GTEST_SKIP() << "skipped: sweethome3d-furniture is not installed (scripts/setup installs it)";
  std::size_t read = 0;
  for (const ZipMember& m : listZip(archive)) {
    if (m.name.empty() || m.name.back() == '/') continue;
    EXPECT_EQ(readZipMember(archive, m).size(), m.size) << m.name;
    ++read;
  }
  EXPECT_GT(read, 500u);
}

}  // namespace
}  // namespace sdfstream
