#include "world/gltf_accessor.h"

#include <algorithm>
#include <cstring>
#include <tuple>
#include <utility>

#include "core/error.h"

namespace sdfstream::gltf {
namespace {

using Kind = InputErrorKind;

// The bytes of `count` elements of `elementSize` read from `bufferView` at `byteOffset` with the
// view's stride (or `elementSize` when it has none); checks every range. Returns data and stride.
std::pair<const unsigned char*, std::size_t> viewBytes(const tinygltf::Model& model,
                                                       int bufferView, std::size_t byteOffset,
                                                       std::size_t count, std::size_t elementSize,
                                                       const std::string& name,
                                                       const std::string& file) {
  if (bufferView < 0 || std::size_t(bufferView) >= model.bufferViews.size())
    throw InputError(Kind::OutOfRange, file,
                     name + ": bufferView " + std::to_string(bufferView) + " does not exist");
  const tinygltf::BufferView& bv = model.bufferViews[std::size_t(bufferView)];
  const std::string bvName = label("bufferView", std::size_t(bufferView));
  if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
    throw InputError(Kind::OutOfRange, file,
                     bvName + ": buffer " + std::to_string(bv.buffer) + " does not exist");
  const tinygltf::Buffer& buf = model.buffers[std::size_t(bv.buffer)];
  if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset)
    throw InputError(Kind::Truncated, file,
                     bvName + " needs bytes up to " +
                         std::to_string(bv.byteOffset + bv.byteLength) + " of buffer " +
                         std::to_string(bv.buffer) + ", which has only " +
                         std::to_string(buf.data.size()));
  const std::size_t stride = bv.byteStride ? bv.byteStride : elementSize;
  if (stride < elementSize)
    throw InputError(Kind::Malformed, file, bvName + ": byteStride is smaller than an element");
  if (count == 0) return {nullptr, stride};
  // count <= byteLength first, so the products below cannot overflow.
  if (count > bv.byteLength || byteOffset > bv.byteLength ||
      (count - 1) * stride + elementSize > bv.byteLength - byteOffset)
    throw InputError(Kind::OutOfRange, file,
                     name + " (" + std::to_string(count) + " elements from byte " +
                         std::to_string(byteOffset) + ") reads past the end of " + bvName);
  return {buf.data.data() + bv.byteOffset + byteOffset, stride};
}

std::size_t nonNegative(int v, const std::string& what, const std::string& file) {
  if (v < 0) throw InputError(Kind::Malformed, file, what + " is negative");
  return std::size_t(v);
}

// glTF 2.0 "Sparse Accessors": the base (or zeros), then values[k] replaces element indices[k].
std::shared_ptr<std::vector<unsigned char>> materialiseSparse(const tinygltf::Model& model,
                                                              const tinygltf::Accessor& acc,
                                                              std::size_t elementSize,
                                                              const std::string& name,
                                                              const std::string& file) {
  if (acc.count > kMaxSparseAccessorBytes / elementSize)
    throw InputError(Kind::TooLarge, file,
                     name + ": " + std::to_string(acc.count) + " elements exceed the " +
                         std::to_string(kMaxSparseAccessorBytes >> 20) +
                         " MiB limit of a sparse accessor");
  auto out = std::make_shared<std::vector<unsigned char>>(acc.count * elementSize, 0);
  if (acc.bufferView >= 0 && acc.count > 0) {
    const auto [base, stride] =
        viewBytes(model, acc.bufferView, acc.byteOffset, acc.count, elementSize, name, file);
    for (std::size_t i = 0; i < acc.count; ++i)
      std::memcpy(out->data() + i * elementSize, base + i * stride, elementSize);
  }
  const auto& sp = acc.sparse;
  const std::size_t n = nonNegative(sp.count, name + ": sparse.count", file);
  if (n > acc.count)
    throw InputError(Kind::OutOfRange, file,
                     name + ": sparse.count " + std::to_string(n) + " exceeds the accessor's " +
                         std::to_string(acc.count) + " elements");
  if (n == 0) return out;
  const int indexType = sp.indices.componentType;
  if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    throw InputError(Kind::Malformed, file,
                     name + ": sparse.indices.componentType must be an unsigned integer");
  AccessorView indices;
  indices.componentType = indexType;
  indices.components = 1;
  indices.count = n;
  const std::size_t indexSize = std::size_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(indexType)));
  std::tie(indices.data, indices.stride) =
      viewBytes(model, sp.indices.bufferView,
                nonNegative(sp.indices.byteOffset, name + ": sparse.indices.byteOffset", file), n,
                indexSize, name + " sparse.indices", file);
  const auto [values, valueStride] =
      viewBytes(model, sp.values.bufferView,
                nonNegative(sp.values.byteOffset, name + ": sparse.values.byteOffset", file), n,
                elementSize, name + " sparse.values", file);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t target = indices.index(k);
    if (target >= acc.count)
      throw InputError(Kind::OutOfRange, file,
                       name + ": sparse index " + std::to_string(target) + " at position " +
                           std::to_string(k) + " is not below the count " +
                           std::to_string(acc.count));
    std::memcpy(out->data() + target * elementSize, values + k * valueStride, elementSize);
  }
  return out;
}

}  // namespace

double AccessorView::get(std::size_t i, int c) const {
  const unsigned char* p = data + i * stride;
  auto load = [&](auto tag) {
    decltype(tag) v;
    std::memcpy(&v, p + std::size_t(c) * sizeof(v), sizeof(v));
    return v;
  };
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return load(float{});
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const double v = load(std::uint8_t{});
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = load(std::uint16_t{});
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return load(std::uint32_t{});
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = load(std::int8_t{});
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = load(std::int16_t{});
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
  }
  return 0.0;
}

std::uint32_t AccessorView::index(std::size_t i) const {
  const unsigned char* p = data + i * stride;
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return p[0];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    default: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

std::string label(const char* what, std::size_t i) {
  return std::string(what) + " " + std::to_string(i);
}

AccessorView viewAccessor(const tinygltf::Model& model, int index, const std::string& file) {
  if (index < 0 || std::size_t(index) >= model.accessors.size())
    throw InputError(Kind::OutOfRange, file,
                     label("accessor", std::size_t(index)) + " does not exist (the file has " +
                         std::to_string(model.accessors.size()) + ")");
  const tinygltf::Accessor& acc = model.accessors[std::size_t(index)];
  const std::string name = label("accessor", std::size_t(index));
  const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(acc.componentType));
  const int components = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
  if (componentSize <= 0 || components <= 0)
    throw InputError(Kind::Malformed, file, name + ": unknown componentType or type");
  const std::size_t elementSize = std::size_t(componentSize) * std::size_t(components);
  AccessorView view;
  view.count = acc.count;
  view.componentType = acc.componentType;
  view.components = components;
  view.normalized = acc.normalized;
  if (acc.sparse.isSparse) {
    view.owned = materialiseSparse(model, acc, elementSize, name, file);
    view.data = view.owned->data();
    view.stride = elementSize;
    return view;
  }
  if (acc.bufferView < 0) throw InputError(Kind::MissingData, file, name + " has no bufferView");
  std::tie(view.data, view.stride) =
      viewBytes(model, acc.bufferView, acc.byteOffset, acc.count, elementSize, name, file);
  return view;
}

}  // namespace sdfstream::gltf
