// Internal to the glTF importer: bounds-checked reads of accessors, sparse ones included.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace sdfstream::gltf {

// The most bytes one sparse accessor may expand to (its count is not bounded by a buffer when it
// has no bufferView: a 30-byte file could otherwise ask for gigabytes of zeros).
inline constexpr std::size_t kMaxSparseAccessorBytes = std::size_t(1) << 30;

// A strided view of one accessor's elements. Sparse accessors are materialised into `owned`
// (base values or zeros, then the sparse substitutions), so readers never see the difference.
struct AccessorView {
  const unsigned char* data = nullptr;
  std::size_t stride = 0;
  std::size_t count = 0;
  int componentType = 0;
  int components = 0;
  bool normalized = false;
  std::shared_ptr<const std::vector<unsigned char>> owned;

  // Component c of element i as a double; normalized integers mapped to [0,1] / [-1,1].
  double get(std::size_t i, int c) const;
  // Element i of an unsigned integer scalar accessor.
  std::uint32_t index(std::size_t i) const;
};

std::string label(const char* what, std::size_t i);

// Throws InputError: OutOfRange (an index or a byte range outside its array), Truncated (a
// bufferView longer than its buffer), Malformed (bad types or strides), MissingData (no
// bufferView and not sparse), TooLarge (a sparse accessor over kMaxSparseAccessorBytes).
AccessorView viewAccessor(const tinygltf::Model& model, int index, const std::string& file);

}  // namespace sdfstream::gltf
