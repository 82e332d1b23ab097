#include "core/atomic_dir.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <fstream>

#include "core/error.h"

namespace fs = std::filesystem;

namespace sdfstream {
namespace {
std::atomic<int> gCounter{0};

fs::path siblingName(const fs::path& dest, const char* tag) {
  fs::path clean = dest.lexically_normal();
  if (clean.filename().empty()) clean = clean.parent_path();
  return clean.parent_path() / (clean.filename().string() + tag + std::to_string(::getpid()) + "-" +
                                std::to_string(gCounter++));
}
}  // namespace

AtomicDirectory::AtomicDirectory(fs::path dest) : dest_(std::move(dest)) {
  if (dest_.filename().empty()) dest_ = dest_.parent_path();
  staging_ = siblingName(dest_, ".tmp-");
  std::error_code ec;
  if (!dest_.parent_path().empty()) fs::create_directories(dest_.parent_path(), ec);
  if (!fs::create_directory(staging_, ec) || ec)
    throw InputError(InputErrorKind::Io, dest_.string(),
                     "cannot create staging directory: " + ec.message());
}

AtomicDirectory::~AtomicDirectory() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
}

void AtomicDirectory::commit() {
  std::error_code ec;
  fs::path backup;
  if (fs::exists(dest_, ec)) {
    backup = siblingName(dest_, ".old-");
    fs::rename(dest_, backup, ec);
    if (ec)
      throw InputError(InputErrorKind::Io, dest_.string(),
                       "cannot move existing output aside: " + ec.message());
  }
  fs::rename(staging_, dest_, ec);
  if (ec) {
    std::error_code ignored;
    if (!backup.empty()) fs::rename(backup, dest_, ignored);
    throw InputError(InputErrorKind::Io, dest_.string(), "cannot rename into place: " + ec.message());
  }
  committed_ = true;
  if (!backup.empty()) fs::remove_all(backup, ec);
}

void writeFileAtomically(const fs::path& path, const void* data, size_t size) {
  fs::path tmp = siblingName(path, ".tmp-");
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(InputErrorKind::Io, path.string(), "cannot open for writing");
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw InputError(InputErrorKind::Io, path.string(), "write failed (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(InputErrorKind::Io, path.string(), "cannot rename into place");
  }
}

}  // namespace sdfstream
