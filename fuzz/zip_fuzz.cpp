// .zip archives: listZip, then readZipMember on every member (world/zip_reader.h), the way
// generateWorld pulls heightmaps and furniture out of Debian's archives.
#include "fuzz/fuzz_support.h"
#include "world/zip_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sdfstream;
  const auto path = fuzz::writeFile("zip/input.zip", data, size);
  fuzz::expectOnlyInputError([&] {
    const std::vector<ZipMember> members = listZip(path);
    // A listing is cheap to make long (a member is 46 bytes); reading a few covers the reader.
    for (std::size_t i = 0; i < members.size() && i < 16; ++i) {
      // Members fail independently: one bad member must not hide what reading the next does.
      fuzz::expectOnlyInputError([&] {
        const std::vector<std::uint8_t> bytes = readZipMember(path, members[i]);
        fuzz::contract(bytes.size() == (members[i].method == 0 ? members[i].compressedSize
                                                                : members[i].size),
                       "a member's bytes have its declared size");
      });
    }
  });
  return 0;
}
