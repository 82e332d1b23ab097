#include "world/obj_import.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>

#include <stb_image.h>

#include "core/error.h"
#include "world/png_chunks.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

constexpr double kMaxTexturePixels = 64.0 * (1 << 20);

float srgbToLinear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// Three finite numbers after `tag` (a vertex's "v", a material's "Kd"/"Ke"); fail(kind, what)
// throws, naming the file and line.
template <typename Fail>
glm::vec3 readTriple(std::istringstream& ls, const char* tag, const std::string& nonFinite,
                     const Fail& fail) {
  glm::vec3 v(0.0f);
  if (!(ls >> v.x >> v.y >> v.z))
    fail(InputErrorKind::Malformed, std::string("expected 3 numbers after '") + tag + "'");
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    fail(InputErrorKind::NonFinite, nonFinite);
  return v;
}

// A decoded map_Kd image (linear RGB), tapped at face UVs to find a material's mean colour.
struct TextureImage {
  int width = 0, height = 0;
  std::vector<glm::vec3> texels;
  glm::vec3 mean{0.0f};

  // Nearest texel at (u, v), repeating; OBJ's v runs up from the bottom row.
  glm::vec3 at(glm::vec2 uv) const {
    const double u = uv.x - std::floor(uv.x), v = uv.y - std::floor(uv.y);
    const int x = std::min(width - 1, int(u * width));
    const int y = std::min(height - 1, int((1.0 - v) * height));
    return texels[std::size_t(y) * width + x];
  }
};

// Decodes an image; nullptr when the file cannot be read or decoded, or is over 64 Mpixels. A
// PNG's chunks are checked first (world/png_chunks.h): a malformed PNG is the one error thrown,
// naming the texture.
std::shared_ptr<TextureImage> readTexture(const fs::path& file) {
  // A regular file only: a name the OBJ chose may be a directory, a device or a FIFO.
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return nullptr;
  std::ifstream probe(file, std::ios::binary);
  if (!probe) return nullptr;
  if (hasPngSignature(probe)) checkPngChunks(probe, fs::file_size(file, ec), file.string());
  probe.close();
  int w = 0, h = 0, channels = 0;
  if (stbi_info(file.c_str(), &w, &h, &channels) == 0 || double(w) * double(h) > kMaxTexturePixels)
    return nullptr;
  unsigned char* data = stbi_load(file.c_str(), &w, &h, &channels, 3);
  if (!data) return nullptr;
  auto image = std::make_shared<TextureImage>();
  image->width = w;
  image->height = h;
  image->texels.resize(std::size_t(w) * h);
  glm::dvec3 sum(0.0);
  for (std::size_t i = 0; i < image->texels.size(); ++i) {
    for (int c = 0; c < 3; ++c) image->texels[i][c] = srgbToLinear(data[i * 3 + c] / 255.0f);
    sum += glm::dvec3(image->texels[i]);
  }
  stbi_image_free(data);
  image->mean = glm::vec3(sum / double(image->texels.size()));
  return image;
}

struct LibraryMaterial {
  Material material;
  std::shared_ptr<TextureImage> texture;  // map_Kd, when readable
};

// Reads one MTL library into `out` (by material name). An unreadable library adds nothing.
void readMaterialLibrary(const fs::path& file, std::map<std::string, LibraryMaterial>& out) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return;  // as for textures: no devices or FIFOs
  std::ifstream in(file);
  if (!in) return;
  std::string line;
  int lineNo = 0;
  LibraryMaterial* current = nullptr;
  auto fail = [&](InputErrorKind kind, const std::string& what) {
    throw InputError(kind, file.string(), "line " + std::to_string(lineNo) + ": " + what);
  };
  auto colour = [&](std::istringstream& ls, const char* tag) {
    return glm::max(readTriple(ls, tag, std::string(tag) + " is NaN or infinite", fail),
                    glm::vec3(0.0f));
  };
  while (std::getline(in, line)) {
    ++lineNo;
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#') continue;
    if (tag == "newmtl") {
      std::string name;
      ls >> name;
      current = &out[name];
      current->material.name = name;
      current->material.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    } else if (current && tag == "Kd") {
      current->material.baseColorFactor = glm::vec4(colour(ls, "Kd"), 1.0f);
    } else if (current && tag == "Ke") {
      current->material.emissive = colour(ls, "Ke");
    } else if (current && tag == "map_Kd") {
      std::string token, last;
      while (ls >> token) last = token;  // options such as "-s 1 1 1" come before the name
      if (!last.empty()) current->texture = readTexture(file.parent_path() / last);
    }
  }
}

// A face's texture taps for its material's mean colour.
struct TextureTaps {
  std::shared_ptr<TextureImage> texture;
  glm::dvec3 sum{0.0};
  double weight = 0.0;
};

// Parses one index of a face corner ("i", "i/t", "i//n", "i/t/n": `part` 0 = i, 1 = t) into a
// 0-based index below `size`. A bad position index fails (the face cannot be built); a texture
// coordinate index only tints a material, so an absent or bad one is nullopt (exporters do write
// them one past the end).
std::optional<std::uint32_t> cornerIndex(
    const std::string& token, int part, std::size_t size,
    const std::function<void(InputErrorKind, const std::string&)>& fail) {
  std::size_t begin = 0;
  for (int p = 0; p < part; ++p) {
    begin = token.find('/', begin);
    if (begin == std::string::npos) return std::nullopt;
    ++begin;
  }
  const std::size_t end = std::min(token.find('/', begin), token.size());
  long index = 0;
  auto [ptr, ec] = std::from_chars(token.data() + begin, token.data() + end, index);
  const long resolved = index > 0 ? index - 1 : long(size) + index;
  const bool parsed = ec == std::errc() && ptr == token.data() + end && index != 0;
  if (part > 0)
    return parsed && resolved >= 0 && resolved < long(size)
               ? std::optional<std::uint32_t>(std::uint32_t(resolved))
               : std::nullopt;
  if (!parsed) fail(InputErrorKind::Malformed, "bad face index '" + token + "'");
  if (resolved < 0 || resolved >= long(size))
    fail(InputErrorKind::OutOfRange, "face index " + token + " outside the " +
                                         std::to_string(size) + " vertices defined so far");
  return std::uint32_t(resolved);
}

}  // namespace

TriangleScene loadObj(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(InputErrorKind::Io, path.string(), "cannot open file");
  TriangleScene scene;
  scene.source = path.filename().string();
  Material grey;
  grey.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  grey.name = "default";
  scene.materials.push_back(grey);
  std::map<std::string, LibraryMaterial> library;
  std::set<std::string> librariesRead;
  std::map<std::string, std::uint32_t> used;  // material name → index in scene.materials
  std::vector<TextureTaps> taps(1);           // one per scene material
  std::uint32_t material = 0;
  std::vector<glm::vec2> texcoords;

  std::string line;
  int lineNo = 0;
  const std::function<void(InputErrorKind, const std::string&)> fail =
      [&](InputErrorKind kind, const std::string& what) {
        throw InputError(kind, path.string(), "line " + std::to_string(lineNo) + ": " + what);
      };
  std::vector<std::uint32_t> face;
  while (std::getline(in, line)) {
    ++lineNo;
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      scene.positions.push_back(readTriple(ls, "v", "vertex is NaN or infinite", fail));
    } else if (tag == "vt") {
      glm::vec2 t;
      if (!(ls >> t.x >> t.y)) fail(InputErrorKind::Malformed, "expected 2 numbers after 'vt'");
      if (!std::isfinite(t.x) || !std::isfinite(t.y))
        fail(InputErrorKind::NonFinite, "texture coordinate is NaN or infinite");
      texcoords.push_back(t);
    } else if (tag == "mtllib") {
      std::string name;
      while (ls >> name)  // each library once, however often it is named
        if (librariesRead.insert(name).second)
          readMaterialLibrary(path.parent_path() / name, library);
    } else if (tag == "usemtl") {
      std::string name;
      ls >> name;
      auto [it, added] = used.try_emplace(name, std::uint32_t(scene.materials.size()));
      if (added) {
        auto found = library.find(name);
        Material m = found != library.end() ? found->second.material : grey;
        m.name = name;
        scene.materials.push_back(m);
        taps.push_back({found != library.end() ? found->second.texture : nullptr});
      }
      material = it->second;
    } else if (tag == "f") {
      face.clear();
      glm::vec2 uvSum(0.0f);
      int uvCorners = 0;
      std::string token;
      while (ls >> token) {
        face.push_back(*cornerIndex(token, 0, scene.positions.size(), fail));
        if (auto t = cornerIndex(token, 1, texcoords.size(), fail)) {
          uvSum += texcoords[*t];
          ++uvCorners;
        }
      }
      if (face.size() < 3) fail(InputErrorKind::Malformed, "face with fewer than 3 vertices");
      TextureTaps& tap = taps[material];
      if (tap.texture && uvCorners == int(face.size())) {
        // Weighted by the face's area: a tree's few large leaf cards outweigh its many small cones.
        double area = 0.0;
        for (std::size_t i = 1; i + 1 < face.size(); ++i)
          area += 0.5 * glm::length(glm::cross(
                            glm::dvec3(scene.positions[face[i]] - scene.positions[face[0]]),
                            glm::dvec3(scene.positions[face[i + 1]] - scene.positions[face[0]])));
        tap.sum += area * glm::dvec3(tap.texture->at(uvSum / float(uvCorners)));
        tap.weight += area;
      }
      for (std::size_t i = 1; i + 1 < face.size(); ++i) {  // fan-triangulate polygons
        scene.triangles.push_back({face[0], face[i], face[i + 1]});
        scene.triangleMaterial.push_back(material);
      }
    }
  }
  if (scene.triangles.empty()) throw InputError(InputErrorKind::Empty, path.string(), "no faces");
  // A textured material's colour: Kd times its texture's area-weighted mean at the faces' UV
  // centroids (an atlas shared by leaves and bark gives each its own part), or over the whole
  // image when its faces carry no texture coordinates.
  for (std::size_t m = 0; m < taps.size(); ++m)
    if (taps[m].texture) {
      const glm::vec3 mean =
          taps[m].weight > 0.0 ? glm::vec3(taps[m].sum / taps[m].weight) : taps[m].texture->mean;
      scene.materials[m].baseColorFactor *= glm::vec4(mean, 1.0f);
    }
  scene.uvs.assign(scene.positions.size(), glm::vec2(0.0f));
  return scene;
}

}  // namespace sdfstream
