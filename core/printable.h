// Untrusted text made safe to quote in a one-line error (core/error.h): a name read from a file
// (a zip member, a JSON key, a grid name) may hold a newline, a terminal escape or a megabyte.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace sdfstream {

// The longest quoted text kept, in bytes of the input; longer text ends in "...". Enough for any
// real file or key name, short enough that a hostile one cannot flood a log line.
inline constexpr std::size_t kMaxPrintableBytes = 512;

// s with every control byte (below 0x20, and 0x7F) written as \xNN and a backslash as \\, cut
// to kMaxPrintableBytes. Bytes of 0x80 and up pass unchanged, so UTF-8 names stay readable.
inline std::string printable(std::string_view s) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  const std::size_t n = s.size() < kMaxPrintableBytes ? s.size() : kMaxPrintableBytes;
  out.reserve(n + 8);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == '\\') {
      out += "\\\\";
    } else if (c < 0x20 || c == 0x7F) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    } else {
      out += char(c);
    }
  }
  if (n < s.size()) out += "...";
  return out;
}

}  // namespace sdfstream
