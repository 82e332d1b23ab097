#include "world/obj_import.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.h"

namespace sdfstream {

TriangleScene loadObj(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(InputErrorKind::Io, path.string(), "cannot open file");
  TriangleScene scene;
  scene.source = path.filename().string();
  Material grey;
  grey.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  grey.name = "default";
  scene.materials.push_back(grey);

  std::string line;
  int lineNo = 0;
  auto fail = [&](InputErrorKind kind, const std::string& what) {
    throw InputError(kind, path.string(), "line " + std::to_string(lineNo) + ": " + what);
  };
  std::vector<std::uint32_t> face;
  while (std::getline(in, line)) {
    ++lineNo;
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      glm::vec3 p;
      if (!(ls >> p.x >> p.y >> p.z)) fail(InputErrorKind::Malformed, "expected 3 numbers after 'v'");
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(InputErrorKind::NonFinite, "vertex is NaN or infinite");
      scene.positions.push_back(p);
    } else if (tag == "f") {
      face.clear();
      std::string token;
      while (ls >> token) {
        // "i", "i/t", "i//n" or "i/t/n": only the position index matters here.
        long index = 0;
        auto end = token.find('/');
        std::string_view head(token.data(), end == std::string::npos ? token.size() : end);
        auto [ptr, ec] = std::from_chars(head.data(), head.data() + head.size(), index);
        if (ec != std::errc() || ptr != head.data() + head.size() || index == 0)
          fail(InputErrorKind::Malformed, "bad face index '" + token + "'");
        long resolved = index > 0 ? index - 1 : long(scene.positions.size()) + index;
        if (resolved < 0 || resolved >= long(scene.positions.size()))
          fail(InputErrorKind::OutOfRange, "face index " + token + " outside the " +
                                               std::to_string(scene.positions.size()) +
                                               " vertices defined so far");
        face.push_back(std::uint32_t(resolved));
      }
      if (face.size() < 3) fail(InputErrorKind::Malformed, "face with fewer than 3 vertices");
      for (std::size_t i = 1; i + 1 < face.size(); ++i) {  // fan-triangulate polygons
        scene.triangles.push_back({face[0], face[i], face[i + 1]});
        scene.triangleMaterial.push_back(0);
      }
    }
  }
  if (scene.triangles.empty()) throw InputError(InputErrorKind::Empty, path.string(), "no faces");
  scene.uvs.assign(scene.positions.size(), glm::vec2(0.0f));
  return scene;
}

}  // namespace sdfstream
