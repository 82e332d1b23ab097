#include "world/asset_proxy.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <vector>

#include <meshoptimizer.h>

#include "core/error.h"

namespace sdfstream {

std::size_t writeProxyObj(const TriangleScene& scene, std::size_t targetTriangles,
                          const std::filesystem::path& obj) {
  const std::size_t materials = scene.materials.size();
  std::vector<std::vector<unsigned>> byMaterial(materials);
  for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
    const std::uint32_t m = std::min<std::uint32_t>(scene.triangleMaterial[t], materials - 1);
    for (int c = 0; c < 3; ++c) byMaterial[m].push_back(scene.triangles[t][c]);
  }
  const std::size_t total = std::max<std::size_t>(1, scene.triangles.size());
  std::vector<std::vector<unsigned>> kept(materials);
  std::vector<int> remap(scene.positions.size(), -1);
  std::vector<glm::vec3> positions;
  for (std::size_t m = 0; m < materials; ++m) {
    const std::vector<unsigned>& in = byMaterial[m];
    if (in.empty()) continue;
    const std::size_t share = std::max<std::size_t>(12, targetTriangles * (in.size() / 3) / total);
    std::vector<unsigned>& out = kept[m];
    out.resize(in.size());
    if (share * 3 < in.size())
      out.resize(meshopt_simplifySloppy(out.data(), in.data(), in.size(), &scene.positions[0].x,
                                        scene.positions.size(), sizeof(glm::vec3), share * 3, 1.0f,
                                        nullptr));
    else
      out = in;
    for (unsigned& i : out) {
      if (remap[i] < 0) {
        remap[i] = int(positions.size());
        positions.push_back(scene.positions[i]);
      }
      i = unsigned(remap[i]);
    }
  }

  std::filesystem::path mtl = obj;
  mtl.replace_extension(".mtl");
  std::ofstream o(obj), l(mtl);
  if (!l) throw InputError(InputErrorKind::Io, mtl.string(), "cannot write");
  o << "# " << scene.source << " simplified to flat-coloured stand-in (sdfstream)\n";
  o << "mtllib " << mtl.filename().string() << "\n";
  char line[160];
  for (const glm::vec3& p : positions) {
    std::snprintf(line, sizeof line, "v %.5g %.5g %.5g\n", p.x, p.y, p.z);
    o << line;
  }
  std::size_t written = 0;
  for (std::size_t m = 0; m < materials; ++m) {
    if (kept[m].empty()) continue;
    const Material& mat = scene.materials[m];
    std::snprintf(line, sizeof line, "newmtl m%zu\nKd %.4f %.4f %.4f\nKe %.4f %.4f %.4f\n", m,
                  mat.baseColorFactor.r, mat.baseColorFactor.g, mat.baseColorFactor.b,
                  mat.emissive.r, mat.emissive.g, mat.emissive.b);
    l << line;
    o << "usemtl m" << m << "\n";
    for (std::size_t i = 0; i + 2 < kept[m].size(); i += 3, ++written) {
      std::snprintf(line, sizeof line, "f %u %u %u\n", kept[m][i] + 1, kept[m][i + 1] + 1,
                    kept[m][i + 2] + 1);
      o << line;
    }
  }
  if (!o || !l) throw InputError(InputErrorKind::Io, obj.string(), "cannot write");
  return written;
}

}  // namespace sdfstream
