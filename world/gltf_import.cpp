#include "world/gltf_import.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/error.h"
#include "world/gltf_accessor.h"
#include "world/gltf_document.h"
#include "world/gltf_lights.h"
#include "world/gltf_materials.h"

namespace sdfstream {
namespace {

using Kind = InputErrorKind;
using gltf::AccessorView;
using gltf::label;
using gltf::viewAccessor;

// ---------------------------------------------------------------------------------------------
// Scene assembly.

glm::dmat4 localTransform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3) m = glm::translate(m, glm::make_vec3(node.translation.data()));
  if (node.rotation.size() == 4) {
    const auto& q = node.rotation;
    m *= glm::mat4_cast(glm::normalize(glm::dquat(q[3], q[0], q[1], q[2])));
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::make_vec3(node.scale.data()));
  return m;
}

bool isFloat(const AccessorView& a) { return a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT; }

// KHR_mesh_quantization widens what positions and UVs may be stored as: 8- and 16-bit integers,
// normalized or not (the node transform then dequantizes). 32-bit integers stay refused.
bool isQuantizable(const AccessorView& a) {
  return isFloat(a) || a.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
         a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
         a.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
         a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
}

struct Importer {
  const gltf::Document& doc;
  const tinygltf::Model& model;
  const std::string& file;
  TriangleScene scene;
  std::vector<SceneLight> lightDefinitions;
  int defaultMaterial = -1;

  [[noreturn]] void fail(Kind kind, const std::string& problem) const {
    throw InputError(kind, file, problem);
  }

  std::uint32_t materialFor(int index, const std::string& where) {
    if (index >= 0) {
      if (std::size_t(index) >= model.materials.size())
        fail(Kind::OutOfRange, where + ": material " + std::to_string(index) + " does not exist");
      return std::uint32_t(index);
    }
    if (defaultMaterial < 0) {
      Material grey;
      grey.baseColorFactor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
      grey.name = "default";
      scene.materials.push_back(grey);
      defaultMaterial = int(scene.materials.size() - 1);
    }
    return std::uint32_t(defaultMaterial);
  }

  // One UV set of a primitive into `uvs` at `base`; a scene without the set so far gets zeros
  // for the earlier vertices (TEXCOORD_1 stays empty until some primitive has one).
  void importUvs(const tinygltf::Primitive& prim, const char* name, std::vector<glm::vec2>& uvs,
                 std::size_t base, std::size_t vertexCount, const std::string& where) {
    auto uv = prim.attributes.find(name);
    if (uv == prim.attributes.end()) {
      if (!uvs.empty()) uvs.resize(base + vertexCount, glm::vec2(0.0f));
      return;
    }
    const AccessorView view = viewAccessor(model, uv->second, file);
    if (view.components != 2 || !isQuantizable(view))
      fail(Kind::Malformed, where + ": " + name +
                                " must be VEC2 of float or (KHR_mesh_quantization) 8/16-bit integers");
    if (view.count != vertexCount)
      fail(Kind::Malformed, where + ": " + name + " and POSITION counts differ");
    uvs.resize(base + vertexCount, glm::vec2(0.0f));
    for (std::size_t i = 0; i < vertexCount; ++i) {
      glm::vec2 t(float(view.get(i, 0)), float(view.get(i, 1)));
      if (!std::isfinite(t.x) || !std::isfinite(t.y)) t = glm::vec2(0.0f);
      uvs[base + i] = t;
    }
  }

  void importPrimitive(const tinygltf::Primitive& prim, const glm::dmat4& world,
                       const std::string& where) {
    if (prim.mode >= 0 && prim.mode <= 3) return;  // points and lines
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
      fail(Kind::Malformed, where + ": unknown mode " + std::to_string(prim.mode));
    auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) fail(Kind::MissingData, where + " has no POSITION");
    const AccessorView positions = viewAccessor(model, pos->second, file);
    if (!isQuantizable(positions) || positions.components != 3)
      fail(Kind::Malformed,
           where + ": POSITION must be VEC3 of float or (KHR_mesh_quantization) 8/16-bit integers");

    const std::size_t base = scene.positions.size();
    const std::size_t vertexCount = positions.count;
    if (base + vertexCount > std::size_t(UINT32_MAX))
      fail(Kind::OutOfRange, where + ": more than 2^32 vertices in the scene");
    for (std::size_t i = 0; i < vertexCount; ++i) {
      const glm::dvec3 p(positions.get(i, 0), positions.get(i, 1), positions.get(i, 2));
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(Kind::NonFinite, where + ": POSITION accessor " + std::to_string(pos->second) +
                                  ", vertex " + std::to_string(i) + " is not finite");
      const glm::vec3 w(world * glm::dvec4(p, 1.0));
      if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))
        fail(Kind::NonFinite,
             where + ": vertex " + std::to_string(i) + " is not finite after its node transform");
      scene.positions.push_back(w);
    }

    scene.uvs.resize(scene.positions.size(), glm::vec2(0.0f));  // set 0 always has one per vertex
    importUvs(prim, "TEXCOORD_0", scene.uvs, base, vertexCount, where);
    importUvs(prim, "TEXCOORD_1", scene.uvs1, base, vertexCount, where);

    std::vector<std::uint32_t> idx;
    if (prim.indices >= 0) {
      const AccessorView indices = viewAccessor(model, prim.indices, file);
      if (indices.components != 1 ||
          (indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
           indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
           indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        fail(Kind::Malformed, where + ": indices must be unsigned integer scalars");
      idx.resize(indices.count);
      for (std::size_t i = 0; i < indices.count; ++i) {
        idx[i] = indices.index(i);
        if (idx[i] >= vertexCount)
          fail(Kind::OutOfRange,
               where + ": index " + std::to_string(idx[i]) + " at position " + std::to_string(i) +
                   " of accessor " + std::to_string(prim.indices) +
                   " is not below the vertex count " + std::to_string(vertexCount));
      }
    } else {
      idx.resize(vertexCount);
      for (std::size_t i = 0; i < vertexCount; ++i) idx[i] = std::uint32_t(i);
    }

    const std::uint32_t material = materialFor(prim.material, where);
    const bool flip = glm::determinant(world) < 0.0;  // mirrored: keep CCW winding
    auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
      const std::uint32_t o = std::uint32_t(base);
      scene.triangles.push_back(flip ? glm::uvec3(a + o, c + o, b + o)
                                     : glm::uvec3(a + o, b + o, c + o));
      scene.triangleMaterial.push_back(material);
    };
    if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
      for (std::size_t i = 0; i + 2 < idx.size(); i += 3) emit(idx[i], idx[i + 1], idx[i + 2]);
    } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t i = 0; i + 2 < idx.size(); ++i)  // glTF spec: odd triangles swap
        emit(idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]);
    } else {
      for (std::size_t i = 1; i + 1 < idx.size(); ++i) emit(idx[i], idx[i + 1], idx[0]);
    }
  }

  void importMesh(int meshIndex, const glm::dmat4& world, std::size_t node) {
    if (std::size_t(meshIndex) >= model.meshes.size())
      fail(Kind::OutOfRange,
           label("node", node) + ": mesh " + std::to_string(meshIndex) + " does not exist");
    const tinygltf::Mesh& mesh = model.meshes[std::size_t(meshIndex)];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
      importPrimitive(
          mesh.primitives[p], world,
          "meshes[" + std::to_string(meshIndex) + "].primitives[" + std::to_string(p) + "]");
  }

  std::vector<int> rootNodes() const {
    if (model.defaultScene >= 0 || !model.scenes.empty()) {
      const int s = std::max(model.defaultScene, 0);
      if (std::size_t(s) >= model.scenes.size())
        fail(Kind::OutOfRange, "scene " + std::to_string(s) + " does not exist");
      return model.scenes[std::size_t(s)].nodes;
    }
    std::vector<char> isChild(model.nodes.size(), 0);
    for (const tinygltf::Node& n : model.nodes)
      for (int c : n.children)
        if (c >= 0 && std::size_t(c) < isChild.size()) isChild[std::size_t(c)] = 1;
    std::vector<int> roots;
    for (std::size_t i = 0; i < model.nodes.size(); ++i)
      if (!isChild[i]) roots.push_back(int(i));
    return roots;
  }

  // Depth-first with an explicit stack: file-controlled depth must not overflow ours. glTF node
  // hierarchies are disjoint trees, so reaching a node twice means a cycle (or a shared child).
  void importNodes() {
    std::vector<char> visited(model.nodes.size(), 0);
    std::vector<std::pair<int, glm::dmat4>> stack;
    const std::vector<int> roots = rootNodes();
    for (auto it = roots.rbegin(); it != roots.rend(); ++it)
      stack.emplace_back(*it, glm::dmat4(1.0));
    while (!stack.empty()) {
      const auto [n, parent] = stack.back();
      stack.pop_back();
      if (n < 0 || std::size_t(n) >= model.nodes.size())
        fail(Kind::OutOfRange, label("node", std::size_t(n)) + " does not exist");
      if (visited[std::size_t(n)])
        fail(Kind::Malformed,
             label("node", std::size_t(n)) + " is reached twice: the node hierarchy has a cycle");
      visited[std::size_t(n)] = 1;
      const tinygltf::Node& node = model.nodes[std::size_t(n)];
      const glm::dmat4 world = parent * localTransform(node);
      if (node.mesh >= 0) importMesh(node.mesh, world, std::size_t(n));
      if (const int light = gltf::nodeLight(doc.json, std::size_t(n), lightDefinitions.size(), file);
          light >= 0) {
        const SceneLight placed = transformLight(lightDefinitions[std::size_t(light)], world);
        if (!std::isfinite(placed.position.x + placed.position.y + placed.position.z))
          fail(Kind::NonFinite, label("node", std::size_t(n)) + ": light position is not finite");
        if (scene.lights.size() == gltf::kMaxGltfLights)
          fail(Kind::TooLarge, "more than " + std::to_string(gltf::kMaxGltfLights) +
                                   " placed lights");
        scene.lights.push_back(placed);
      }
      for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
        stack.emplace_back(*c, world);
    }
  }
};

}  // namespace

TriangleScene loadGltf(const std::filesystem::path& path) {
  const std::string file = path.string();
  const gltf::Document doc = gltf::loadDocument(path, file);
  Importer importer{doc, doc.model, file, {}, gltf::readLightDefinitions(doc.json, file), -1};
  importer.scene.source = file;
  gltf::MaterialImporter(doc, file, importer.scene).importAll();
  importer.importNodes();
  if (importer.scene.triangles.empty())
    throw InputError(Kind::Empty, file, "the scene has no triangles");
  if (importer.scene.materials.empty()) importer.materialFor(-1, "");
  return std::move(importer.scene);
}

}  // namespace sdfstream
