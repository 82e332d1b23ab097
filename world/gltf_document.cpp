#include "world/gltf_document.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/read_file.h"
#include "world/gltf_meshopt.h"

namespace sdfstream::gltf {
namespace {

using Kind = InputErrorKind;

std::uint32_t readU32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

// Checks the GLB container (header, JSON chunk) and returns the JSON text and the container size.
std::pair<std::string_view, std::size_t> splitGlb(const std::vector<unsigned char>& bytes,
                                                  const std::string& file) {
  const std::size_t size = bytes.size();
  if (size > 0 && std::memcmp(bytes.data(), "glTF", std::min<std::size_t>(size, 4)) != 0)
    throw InputError(Kind::Malformed, file, "not a binary glTF file (bad magic)");
  if (size < 12)
    throw InputError(Kind::Truncated, file,
                     std::to_string(size) + " bytes, shorter than the 12-byte GLB header");
  if (readU32(&bytes[4]) != 2)
    throw InputError(Kind::Version, file,
                     "GLB version " + std::to_string(readU32(&bytes[4])) + ", expected 2");
  const std::size_t length = readU32(&bytes[8]);
  if (length > size)
    throw InputError(Kind::Truncated, file,
                     "GLB header declares " + std::to_string(length) + " bytes but the file has " +
                         std::to_string(size));
  if (length < 20) throw InputError(Kind::Truncated, file, "GLB ends before its JSON chunk");
  const std::size_t jsonLength = readU32(&bytes[12]);
  if (readU32(&bytes[16]) != 0x4E4F534Au)  // "JSON"
    throw InputError(Kind::Malformed, file, "first GLB chunk is not JSON");
  if (jsonLength > length - 20)
    throw InputError(Kind::Truncated, file, "GLB JSON chunk runs past the end of the file");
  return {std::string_view(reinterpret_cast<const char*>(&bytes[20]), jsonLength), length};
}

// tinygltf's messages can span lines and embed whole data URIs: keep the first line, bounded.
[[noreturn]] void throwTinygltfError(const std::string& err, const std::string& file) {
  std::string line = err.substr(0, err.find('\n'));
  if (line.empty()) line = "tinygltf could not load the file";
  if (line.size() > 200) line = line.substr(0, 200) + "...";
  Kind kind = Kind::Malformed;
  if (line.find("File not found") != std::string::npos ||
      line.find("File open error") != std::string::npos)
    kind = Kind::MissingData;
  else if (line.find("size mismatch") != std::string::npos ||
           line.find("Invalid `byteLength'") != std::string::npos ||
           line.find("empty BIN chunk") != std::string::npos ||
           line.find("Invalid glTF binary") != std::string::npos)
    kind = Kind::Truncated;
  throw InputError(kind, file, line);
}

void refuseUnsupportedRequirements(const Json& json, const std::string& file) {
  auto it = json.find("extensionsRequired");
  if (it == json.end()) return;  // checkTypes saw an array of strings
  for (const Json& name : *it) {
    const std::string n = name.get<std::string>();
    if (std::none_of(std::begin(kSupportedRequiredExtensions),
                     std::end(kSupportedRequiredExtensions), [&](const char* s) { return n == s; }))
      throw InputError(
          Kind::Unsupported, file,
          "requires the glTF extension " + n.substr(0, 100) + ", which sdfstream does not support");
  }
}

// Writes a GLB container around `json` and the chunks that followed the original JSON chunk.
std::vector<unsigned char> rebuildGlb(const std::vector<unsigned char>& bytes, std::size_t length,
                                      std::size_t oldJsonLength, const Json& json) {
  std::string text = json.dump();
  text.resize((text.size() + 3) & ~std::size_t(3), ' ');  // chunks are 4-byte aligned
  const std::size_t rest = length - 20 - oldJsonLength;
  std::vector<unsigned char> out(20 + text.size() + rest);
  auto put = [&](std::size_t at, std::uint32_t v) {
    for (int b = 0; b < 4; ++b) out[at + std::size_t(b)] = static_cast<unsigned char>(v >> (8 * b));
  };
  std::memcpy(out.data(), bytes.data(), 8);  // magic, version
  put(8, std::uint32_t(out.size()));
  put(12, std::uint32_t(text.size()));
  put(16, 0x4E4F534Au);  // "JSON"
  std::memcpy(out.data() + 20, text.data(), text.size());
  std::memcpy(out.data() + 20 + text.size(), bytes.data() + 20 + oldJsonLength, rest);
  return out;
}

tinygltf::Model runTinygltf(const std::vector<unsigned char>& bytes, std::size_t length,
                            bool binary, const std::filesystem::path& path,
                            const std::string& file) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  const std::string baseDir = path.parent_path().string();
  const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                                       unsigned(length), baseDir)
                         : loader.LoadASCIIFromString(&model, &err, &warn,
                                                      reinterpret_cast<const char*>(bytes.data()),
                                                      unsigned(length), baseDir);
  if (!ok || !err.empty()) throwTinygltfError(err, file);
  return model;
}

}  // namespace

Document loadDocument(const std::filesystem::path& path, const std::string& file) {
  std::vector<unsigned char> bytes = readWholeFile<std::vector<unsigned char>>(path, file);
  const bool binary = path.extension() == ".glb" ||
                      (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0);
  Document doc;
  std::size_t length = bytes.size();
  std::size_t jsonLength = 0;
  if (binary) {
    const auto [text, glbLength] = splitGlb(bytes, file);
    doc.json = parseAndCheckJson(text, file);
    length = glbLength;
    jsonLength = text.size();
  } else {
    doc.json = parseAndCheckJson(
        std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), file);
  }
  refuseUnsupportedRequirements(doc.json, file);
  // tinygltf cannot load EXT_meshopt_compression's fallback buffers (they have no data); they
  // become one-byte placeholders, and the JSON tinygltf sees changes with them.
  if (replaceMeshoptFallbackBuffers(doc.json)) {
    if (binary) {
      bytes = rebuildGlb(bytes, length, jsonLength, doc.json);
    } else {
      const std::string text = doc.json.dump();
      bytes.assign(text.begin(), text.end());
    }
    length = bytes.size();
  }
  if (length > std::size_t(UINT32_MAX))
    throw InputError(Kind::TooLarge, file, "larger than 4 GiB, the most tinygltf can read");
  doc.model = runTinygltf(bytes, length, binary, path, file);
  decodeMeshoptBufferViews(doc, file);
  return doc;
}

}  // namespace sdfstream::gltf
