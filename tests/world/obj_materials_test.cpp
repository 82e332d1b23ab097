// world/obj_import.h's materials: Kd/Ke from the MTL library, a map_Kd texture's colour at the
// faces' texture coordinates (area-weighted), the forgiving cases viewers tolerate (no library, an
// unknown name, a texture coordinate index one past the end) and the one-line errors of a
// malformed library. Also world/asset_proxy.h: a simplified stand-in keeps its colours.
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/test_data.h"
#include "world/asset_proxy.h"
#include "world/obj_import.h"

namespace sdfstream {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

// A 2x2 binary PPM (stb_image reads PNM): top row green, bottom row red, sRGB 255 = linear 1.
void writeTexture(const fs::path& file) {
  std::string ppm = "P6\n2 2\n255\n";
  for (const char* texel : {"\x00\xff\x00", "\x00\xff\x00", "\xff\x00\x00", "\xff\x00\x00"})
    ppm.append(texel, 3);
  write(file, ppm);
}

// Two quads: a large one whose UVs lie in the texture's top (green) half, a small one in its
// bottom (red) half, both with material "leaf"; one triangle with "paint"; one with "nowhere".
const char* kObj =
    "mtllib scene.mtl\n"
    "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 0 4 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "vt 0.25 0.75\nvt 0.75 0.75\nvt 0.75 0.9\nvt 0.25 0.9\nvt 0.25 0.1\nvt 0.75 0.1\n"
    "usemtl leaf\nf 1/1 2/2 3/3 4/4\nf 5/5 6/6 7/6 8/5\n"
    "usemtl paint\nf 1 2 3\n"
    "usemtl nowhere\nf 1 3 4\n";

TEST(ObjMaterials, KdKeAndTheTextureAtTheFacesUvs) {
  const fs::path dir = test::scratchDir("obj-materials");
  writeTexture(dir / "leaf.ppm");
  write(dir / "scene.mtl",
        "newmtl leaf\nKd 0.5 0.5 0.5\nmap_Kd -s 1 1 1 leaf.ppm\n"
        "newmtl paint\nKd 0.2 0.4 0.6\nKe 3 2 1\n");
  write(dir / "scene.obj", kObj);
  const TriangleScene scene = loadObj(dir / "scene.obj");
  ASSERT_EQ(scene.materials.size(), 4u);  // the grey default, then in order of first use
  EXPECT_EQ(scene.materials[1].name, "leaf");
  // The 16 m² green quad outweighs the 1 m² red one: Kd 0.5
  // times (16·green + 1·red)/17.
  const glm::vec4 leaf = scene.materials[1].baseColorFactor;
  EXPECT_NEAR(leaf.g, 0.5f * 16.0f / 17.0f, 1e-4f);
  EXPECT_NEAR(leaf.r, 0.5f * 1.0f / 17.0f, 1e-4f);
  EXPECT_NEAR(leaf.b, 0.0f, 1e-6f);
  EXPECT_EQ(glm::vec3(scene.materials[2].baseColorFactor), glm::vec3(0.2f, 0.4f, 0.6f));
  EXPECT_EQ(scene.materials[2].emissive, glm::vec3(3.0f, 2.0f, 1.0f));
  EXPECT_EQ(glm::vec3(scene.materials[3].baseColorFactor), glm::vec3(0.8f));  // unknown name
  ASSERT_EQ(scene.triangleMaterial.size(), 6u);
  EXPECT_EQ(scene.triangleMaterial[0], 1u);
  EXPECT_EQ(scene.triangleMaterial[4], 2u);
  EXPECT_EQ(scene.triangleMaterial[5], 3u);
}

TEST(ObjMaterials, MissingLibraryTextureOrTexcoordFallsBackQuietly) {
  const fs::path dir = test::scratchDir("obj-materials-missing");
  write(dir / "scene.obj", kObj);  // scene.mtl absent
  const TriangleScene bare = loadObj(dir / "scene.obj");
  for (const Material& m : bare.materials) EXPECT_EQ(glm::vec3(m.baseColorFactor), glm::vec3(0.8f));

  write(dir / "scene.mtl", "newmtl leaf\nKd 0.5 0.5 0.5\nmap_Kd absent.png\n");
  EXPECT_EQ(glm::vec3(loadObj(dir / "scene.obj").materials[1].baseColorFactor), glm::vec3(0.5f));

  // A texture coordinate index one past the end (Sweet Home 3D's truck has one) only loses that
  // face's tap; the position indices still have to be right.
  writeTexture(dir / "leaf.ppm");
  write(dir / "scene.mtl", "newmtl leaf\nKd 1 1 1\nmap_Kd leaf.ppm\n");
  write(dir / "past.obj",
        "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0.5 0.9\n"
        "usemtl leaf\nf 1/1 2/1 3/1\nf 1/1 2/1 3/2\n");
  const TriangleScene past = loadObj(dir / "past.obj");
  EXPECT_EQ(glm::vec3(past.materials[1].baseColorFactor), glm::vec3(0.0f, 1.0f, 0.0f));
  write(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n");
  EXPECT_THROW(loadObj(dir / "bad.obj"), InputError);
}

TEST(ObjMaterials, MalformedLibraryNamesItsFileAndLine) {
  const fs::path dir = test::scratchDir("obj-materials-bad");
  write(dir / "scene.obj", kObj);
  write(dir / "scene.mtl", "newmtl leaf\n# a comment\nKd 0.5 green 0.5\n");
  try {
    loadObj(dir / "scene.obj");
    FAIL() << "a malformed Kd was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("scene.mtl"), std::string::npos) << what;
    EXPECT_NE(what.find("line 3"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  write(dir / "scene.mtl", "newmtl leaf\nKe 1 nan 1\n");
  EXPECT_THROW(loadObj(dir / "scene.obj"), InputError);
}

TEST(AssetProxy, SimplifiesToTheBudgetAndKeepsFlatColours) {
  // A 64x64 grid of separate quads (a leaf-card soup: no shared edges to collapse) in two
  // materials.
  TriangleScene soup;
  soup.source = "soup";
  soup.materials.resize(2);
  soup.materials[0].baseColorFactor = glm::vec4(0.1f, 0.5f, 0.1f, 1.0f);
  soup.materials[1].baseColorFactor = glm::vec4(0.4f, 0.3f, 0.2f, 1.0f);
  soup.materials[1].emissive = glm::vec3(0.0f, 0.0f, 2.0f);
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) {
      const auto base = std::uint32_t(soup.positions.size());
      const glm::vec3 p(float(i), 0.1f * float((i * 7 + j * 3) % 5), float(j));
      for (const glm::vec3& d :
           {glm::vec3(0), glm::vec3(0.9f, 0, 0), glm::vec3(0.9f, 0, 0.9f), glm::vec3(0, 0, 0.9f)})
        soup.positions.push_back(p + d);
      soup.triangles.push_back({base, base + 1, base + 2});
      soup.triangles.push_back({base, base + 2, base + 3});
      soup.triangleMaterial.insert(soup.triangleMaterial.end(), 2, (i < 48) ? 0u : 1u);
    }
  soup.uvs.assign(soup.positions.size(), glm::vec2(0.0f));
  const fs::path obj = test::scratchDir("asset-proxy") / "soup.obj";
  const std::size_t written = writeProxyObj(soup, 1000, obj);
  EXPECT_LE(written, 1100u);
  EXPECT_GE(written, 100u);
  const TriangleScene back = loadObj(obj);
  EXPECT_EQ(back.triangles.size(), written);
  ASSERT_EQ(back.materials.size(), 3u);  // the default, m0, m1
  EXPECT_NEAR(back.materials[1].baseColorFactor.g, 0.5f, 1e-4f);
  EXPECT_NEAR(back.materials[2].baseColorFactor.r, 0.4f, 1e-4f);
  EXPECT_NEAR(back.materials[2].emissive.b, 2.0f, 1e-4f);
  // Still spans the soup: simplification clusters vertices, it does not drop the far corner.
  EXPECT_GT(back.boundsMax().x, 60.0f);
  EXPECT_GT(back.boundsMax().z, 60.0f);
}

}  // namespace
}  // namespace sdfstream
