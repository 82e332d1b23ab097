// A minimal grayscale PNG writer for tests (8- or 16-bit, zlib "stored" blocks, no compression):
// stb_image_write cannot write 16-bit PNGs, and the tests must not depend on the decoder they test.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace sdfstream::test {

inline std::uint32_t crc32(const std::uint8_t* data, std::size_t n, std::uint32_t crc = 0) {
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// values: width·height samples, row-major; bits 8 or 16 (values above the range are clipped).
inline void writeGrayPng(const std::filesystem::path& file, int width, int height,
                         const std::vector<std::uint16_t>& values, int bits) {
  std::vector<std::uint8_t> raw;  // filter byte 0 + big-endian samples per row
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    for (int x = 0; x < width; ++x) {
      const std::uint16_t v = values[std::size_t(y) * width + x];
      if (bits == 16) {
        raw.push_back(std::uint8_t(v >> 8));
        raw.push_back(std::uint8_t(v & 0xff));
      } else {
        raw.push_back(std::uint8_t(v > 255 ? 255 : v));
      }
    }
  }
  std::vector<std::uint8_t> z = {0x78, 0x01};
  for (std::size_t pos = 0; pos < raw.size() || pos == 0;) {
    const std::size_t n = std::min<std::size_t>(65535, raw.size() - pos);
    z.push_back(pos + n == raw.size() ? 1 : 0);
    z.push_back(std::uint8_t(n & 0xff));
    z.push_back(std::uint8_t(n >> 8));
    z.push_back(std::uint8_t(~n & 0xff));
    z.push_back(std::uint8_t((~n >> 8) & 0xff));
    z.insert(z.end(), raw.begin() + std::ptrdiff_t(pos), raw.begin() + std::ptrdiff_t(pos + n));
    pos += n;
    if (n == 0) break;
  }
  std::uint32_t a = 1, b = 0;
  for (std::uint8_t c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  const std::uint32_t adler = b << 16 | a;
  for (int s = 24; s >= 0; s -= 8) z.push_back(std::uint8_t(adler >> s));

  std::ofstream out(file, std::ios::binary);
  const std::uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  out.write(reinterpret_cast<const char*>(sig), 8);
  auto chunk = [&](const char* type, const std::vector<std::uint8_t>& data) {
    std::vector<std::uint8_t> body(type, type + 4);
    body.insert(body.end(), data.begin(), data.end());
    const std::uint32_t len = std::uint32_t(data.size()), crc = crc32(body.data(), body.size());
    const std::uint8_t l[4] = {std::uint8_t(len >> 24), std::uint8_t(len >> 16),
                               std::uint8_t(len >> 8), std::uint8_t(len)};
    const std::uint8_t c[4] = {std::uint8_t(crc >> 24), std::uint8_t(crc >> 16),
                               std::uint8_t(crc >> 8), std::uint8_t(crc)};
    out.write(reinterpret_cast<const char*>(l), 4);
    out.write(reinterpret_cast<const char*>(body.data()), std::streamsize(body.size()));
    out.write(reinterpret_cast<const char*>(c), 4);
  };
  auto be32 = [](std::uint32_t v) {
    return std::vector<std::uint8_t>{std::uint8_t(v >> 24), std::uint8_t(v >> 16),
                                     std::uint8_t(v >> 8), std::uint8_t(v)};
  };
  std::vector<std::uint8_t> ihdr = be32(std::uint32_t(width));
  const auto h = be32(std::uint32_t(height));
  ihdr.insert(ihdr.end(), h.begin(), h.end());
  ihdr.insert(ihdr.end(), {std::uint8_t(bits), 0, 0, 0, 0});  // grayscale, deflate, no interlace
  chunk("IHDR", ihdr);
  chunk("IDAT", z);
  chunk("IEND", {});
}

}  // namespace sdfstream::test
