#include "world/gltf_meshopt.h"

#include <set>
#include <vector>

#include <meshoptimizer.h>

#include "core/error.h"

namespace sdfstream::gltf {
namespace {

using Kind = InputErrorKind;
constexpr const char* kExtension = "EXT_meshopt_compression";

bool isFallback(const Json& buffer) {
  if (!buffer.is_object()) return false;
  auto ext = buffer.find("extensions");
  if (ext == buffer.end() || !ext->is_object()) return false;
  auto mo = ext->find(kExtension);
  if (mo == ext->end() || !mo->is_object()) return false;
  auto fb = mo->find("fallback");
  return fb != mo->end() && fb->is_boolean() && fb->get<bool>();
}

struct CompressedView {
  std::size_t buffer, byteOffset, byteLength, byteStride, count;
  std::string mode, filter;
};

CompressedView readExtension(const Json& ext, const std::string& where, const std::string& file) {
  const JsonReader r(ext, where, file);
  CompressedView v{r.index("buffer"),      r.index("byteOffset", 0), r.index("byteLength"),
                   r.index("byteStride"),  r.index("count"),         r.string("mode", ""),
                   r.string("filter", "NONE")};
  // Each mode's constraints are those of the spec and of the decoders' own asserts.
  if (v.mode == "ATTRIBUTES") {
    if (v.byteStride == 0 || v.byteStride > 256 || v.byteStride % 4 != 0)
      r.fail("byteStride", "ATTRIBUTES needs a multiple of 4 up to 256");
  } else if (v.mode == "TRIANGLES" || v.mode == "INDICES") {
    if (v.byteStride != 2 && v.byteStride != 4) r.fail("byteStride", v.mode + " needs 2 or 4");
    if (v.mode == "TRIANGLES" && v.count % 3 != 0) r.fail("count", "TRIANGLES needs a multiple of 3");
  } else {
    r.fail("mode", "expected ATTRIBUTES, TRIANGLES or INDICES");
  }
  if (v.filter == "OCTAHEDRAL") {
    if (v.byteStride != 4 && v.byteStride != 8) r.fail("byteStride", "OCTAHEDRAL needs 4 or 8");
  } else if (v.filter == "QUATERNION") {
    if (v.byteStride != 8) r.fail("byteStride", "QUATERNION needs 8");
  } else if (v.filter != "NONE" && v.filter != "EXPONENTIAL") {
    r.fail("filter", "expected NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
  }
  if (v.filter != "NONE" && v.mode != "ATTRIBUTES") r.fail("filter", "only ATTRIBUTES take one");
  return v;
}

std::vector<unsigned char> decode(const CompressedView& v, const unsigned char* src,
                                  const std::string& where, const std::string& file) {
  std::vector<unsigned char> out(v.count * v.byteStride);
  int rc = 0;
  if (v.mode == "ATTRIBUTES")
    rc = meshopt_decodeVertexBuffer(out.data(), v.count, v.byteStride, src, v.byteLength);
  else if (v.mode == "TRIANGLES")
    rc = meshopt_decodeIndexBuffer(out.data(), v.count, v.byteStride, src, v.byteLength);
  else
    rc = meshopt_decodeIndexSequence(out.data(), v.count, v.byteStride, src, v.byteLength);
  if (rc != 0)
    throw InputError(Kind::Malformed, file,
                     where + ": compressed data does not decode (meshoptimizer error " +
                         std::to_string(rc) + ")");
  if (v.filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), v.count, v.byteStride);
  if (v.filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), v.count, v.byteStride);
  if (v.filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), v.count, v.byteStride);
  return out;
}

}  // namespace

bool replaceMeshoptFallbackBuffers(Json& json) {
  auto buffers = json.find("buffers");
  if (buffers == json.end() || !buffers->is_array()) return false;
  bool changed = false;
  for (Json& b : *buffers) {
    if (!isFallback(b)) continue;
    b["uri"] = "data:application/octet-stream;base64,AA==";
    b["byteLength"] = 1;
    changed = true;
  }
  return changed;
}

void decodeMeshoptBufferViews(Document& doc, const std::string& file) {
  std::set<std::size_t> fallbacks;
  if (auto b = doc.json.find("buffers"); b != doc.json.end() && b->is_array())
    for (std::size_t i = 0; i < b->size(); ++i)
      if (isFallback((*b)[i])) fallbacks.insert(i);
  auto views = doc.json.find("bufferViews");
  if (views == doc.json.end() || !views->is_array()) return;
  tinygltf::Model& model = doc.model;
  if (views->size() != model.bufferViews.size())
    throw InputError(Kind::Malformed, file, "bufferViews: tinygltf read a different count");
  std::size_t decodedTotal = 0;
  for (std::size_t i = 0; i < views->size(); ++i) {
    const std::string where = "bufferViews[" + std::to_string(i) + "]";
    const JsonReader view((*views)[i], where, file);
    const Json* ext = view.extension(kExtension);
    tinygltf::BufferView& bv = model.bufferViews[i];
    if (!ext) {
      if (bv.buffer >= 0 && fallbacks.count(std::size_t(bv.buffer)))
        throw InputError(Kind::Malformed, file,
                         where + " reads buffer " + std::to_string(bv.buffer) +
                             ", a meshopt fallback without data, and is not compressed");
      continue;
    }
    const std::string extWhere = where + ".extensions." + kExtension;
    const CompressedView cv = readExtension(*ext, extWhere, file);
    if (cv.buffer >= model.buffers.size() || fallbacks.count(cv.buffer))
      throw InputError(Kind::OutOfRange, file,
                       extWhere + ": buffer " + std::to_string(cv.buffer) + " does not hold data");
    const std::vector<unsigned char>& src = model.buffers[cv.buffer].data;
    if (cv.byteOffset > src.size() || cv.byteLength > src.size() - cv.byteOffset)
      throw InputError(Kind::OutOfRange, file,
                       extWhere + ": bytes " + std::to_string(cv.byteOffset) + "+" +
                           std::to_string(cv.byteLength) + " lie outside buffer " +
                           std::to_string(cv.buffer) + " (" + std::to_string(src.size()) +
                           " bytes)");
    // count * byteStride cannot overflow once count is below the limit (byteStride <= 256).
    const std::size_t bytes = cv.count > kMaxMeshoptDecodedBytes ? kMaxMeshoptDecodedBytes + 1
                                                                 : cv.count * cv.byteStride;
    if (bytes > kMaxMeshoptExpansion * cv.byteLength + 4096)
      throw InputError(Kind::Malformed, file,
                       extWhere + ": " + std::to_string(cv.byteLength) +
                           " compressed bytes cannot decode to " + std::to_string(bytes));
    decodedTotal += bytes;
    if (decodedTotal > kMaxMeshoptDecodedBytes)
      throw InputError(Kind::TooLarge, file,
                       extWhere + ": the compressed views decode to more than " +
                           std::to_string(kMaxMeshoptDecodedBytes >> 20) + " MiB");
    tinygltf::Buffer decoded;
    decoded.data = decode(cv, src.data() + cv.byteOffset, extWhere, file);
    model.buffers.push_back(std::move(decoded));
    bv.buffer = int(model.buffers.size() - 1);
    bv.byteOffset = 0;
    bv.byteLength = bytes;
    bv.byteStride = cv.mode == "ATTRIBUTES" ? cv.byteStride : 0;
  }
}

}  // namespace sdfstream::gltf
