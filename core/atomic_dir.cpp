#include "core/atomic_dir.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

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

// The pid in "<name><tag><pid>-<n>", or 0 when `entry` is not such a sibling of `name`.
pid_t siblingPid(const std::string& entry, const std::string& name, const std::string& tag) {
  const std::string prefix = name + tag;
  if (entry.compare(0, prefix.size(), prefix) != 0) return 0;
  const std::string rest = entry.substr(prefix.size());
  const std::size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos ||
      rest.find_first_not_of("0123456789") != dash ||
      rest.find_first_not_of("0123456789", dash + 1) != std::string::npos || dash + 1 == rest.size())
    return 0;
  try {
    return pid_t(std::stol(rest.substr(0, dash)));
  } catch (const std::exception&) {
    return 0;
  }
}

bool processGone(pid_t pid) { return pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH; }
}  // namespace

void recoverInterruptedOutput(const fs::path& destination) {
  fs::path dest = destination.lexically_normal();
  if (dest.filename().empty()) dest = dest.parent_path();
  const fs::path dir = dest.parent_path().empty() ? fs::path(".") : dest.parent_path();
  const std::string name = dest.filename().string();
  std::error_code ec;
  std::vector<fs::path> stale, backups;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    if (const pid_t pid = siblingPid(entry, name, ".tmp-"); pid > 0 && processGone(pid))
      stale.push_back(it->path());
    else if (const pid_t old = siblingPid(entry, name, ".old-"); old > 0 && processGone(old))
      backups.push_back(it->path());
  }
  for (const fs::path& p : stale) fs::remove_all(p, ec);
  // A backup whose writer died between its two renames is the only copy of the previous output:
  // put it back. Once the new output is in place, a leftover backup is just garbage.
  for (const fs::path& p : backups) {
    if (!fs::exists(dest, ec))
      fs::rename(p, dest, ec);
    else
      fs::remove_all(p, ec);
  }
}

AtomicDirectory::AtomicDirectory(fs::path dest) : dest_(std::move(dest)) {
  if (dest_.filename().empty()) dest_ = dest_.parent_path();
  recoverInterruptedOutput(dest_);
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
