// User-facing errors at I/O boundaries (STYLE.md habit 6, third tier): one line that names the
// file and the problem. Per-frame code never throws; it returns status values instead.
#pragma once

#include <stdexcept>
#include <string>

namespace sdfstream {

// What went wrong with an input, so tests can assert the exact class of a failure.
enum class InputErrorKind {
  Io,            // cannot open / read / write (permissions, missing file)
  Malformed,     // not parseable: bad JSON, wrong types, bad magic
  MissingData,   // a referenced buffer/image/file is absent
  OutOfRange,    // an index or offset points outside its array
  NonFinite,     // NaN or infinity where a finite number is required
  Empty,         // nothing to import (no triangles, no active voxels)
  NotLevelSet,   // a .vdb without a float level-set grid (fog volume, points, ...)
  Truncated,     // the file ends before the data it declares
  TooLarge,      // the requested resolution would exceed the memory limit
  Checksum,      // stored data does not match its checksum
  Version,       // unsupported format version
  Usage,         // bad command-line arguments
  Unsupported,   // valid input that needs a feature sdfstream lacks (e.g. a required glTF extension)
};

const char* toString(InputErrorKind kind);

class InputError : public std::runtime_error {
 public:
  InputError(InputErrorKind kind, std::string file, const std::string& problem)
      : std::runtime_error(file + ": " + problem), kind_(kind), file_(std::move(file)) {}
  InputErrorKind kind() const { return kind_; }
  const std::string& file() const { return file_; }

 private:
  InputErrorKind kind_;
  std::string file_;
};

}  // namespace sdfstream
