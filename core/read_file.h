// Whole-file reads for the readers of untrusted files (glTF/GLB, .vdb, layouts, the object and
// irradiance caches): one place that opens in binary, sizes the buffer from the file system and
// tells a missing file from a failed read. The callers bound what they then parse.
#pragma once

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>

#include "core/error.h"

namespace sdfstream {

// The file's bytes as any contiguous container of chars (std::string, std::vector<char>,
// std::vector<unsigned char>, ...), or nullopt when it cannot be opened or read (a cache miss,
// not an error).
template <class Bytes = std::string>
std::optional<Bytes> tryReadWholeFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  Bytes bytes;
  if (const auto size = std::filesystem::file_size(path, ec); !ec) bytes.reserve(size);
  bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) return std::nullopt;
  return bytes;
}

// The same for a file that must be there: InputError(Io, file, ...) naming the problem
// ("is a directory", "cannot open: <reason>", "read error"); `file` is the name errors show.
template <class Bytes = std::string>
Bytes readWholeFile(const std::filesystem::path& path, const std::string& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(InputErrorKind::Io, file, "is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(InputErrorKind::Io, file, std::string("cannot open: ") + std::strerror(errno));
  Bytes bytes;
  if (const auto size = std::filesystem::file_size(path, ec); !ec) bytes.reserve(size);
  bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(InputErrorKind::Io, file, "read error");
  return bytes;
}

}  // namespace sdfstream
