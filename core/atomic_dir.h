// Atomic directory output: build everything in a sibling temp directory, then rename it into
// place. A failure (exception or crash) before commit() leaves the destination untouched and
// the temp directory is removed by the destructor (RAII), so "nothing is lost"; what a killed
// process leaves behind is cleaned up by the next writer of the same destination.
#pragma once

#include <filesystem>
#include <string>

namespace sdfstream {

class AtomicDirectory {
 public:
  // Creates "<dest>.tmp-<pid>-<n>" beside dest. Throws InputError(Io) if that fails.
  explicit AtomicDirectory(std::filesystem::path dest);
  ~AtomicDirectory();
  AtomicDirectory(const AtomicDirectory&) = delete;
  AtomicDirectory& operator=(const AtomicDirectory&) = delete;

  // Where to write the files.
  const std::filesystem::path& staging() const { return staging_; }

  // Replaces dest with the staged directory. An existing dest is moved aside first and deleted
  // only after the new one is in place; if the final rename fails it is moved back.
  void commit();

 private:
  std::filesystem::path dest_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

// What a process killed while writing `dest` through an AtomicDirectory leaves beside it, put
// right: staging directories ("<dest>.tmp-<pid>-<n>") of processes that no longer exist are
// removed; a backup ("<dest>.old-<pid>-<n>", made during commit) is renamed back to dest when
// dest is missing (the writer died between its two renames) and removed otherwise. Siblings of
// live processes are left alone. The AtomicDirectory constructor calls it; best effort, no throw.
void recoverInterruptedOutput(const std::filesystem::path& dest);

// Writes bytes to path through a temp file + rename (used for single files).
void writeFileAtomically(const std::filesystem::path& path, const void* data, size_t size);

}  // namespace sdfstream
