// The .glb of Gaussians: byte layout as glTF 2.0's GLB container says, values back, classes.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>

#include "sadsplat/common/error.h"
#include "sadsplat/io/gltf_splats.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using json = nlohmann::json;

std::uint32_t wordAt(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

std::vector<ClassInfo> threeClasses() {
  return {{"road", {128, 64, 128}, ""}, {"building", {70, 70, 70}, ""}, {"tree", {0, 200, 0}, ""}};
}

pcl::PointCloud<GaussianPoint> someSplats() {
  auto cloud = test::randomGaussians(50, 21, 3);
  for (auto& p : cloud) {
    for (float& s : p.scale) s = -2.0f + 0.5f * s;
    for (float& v : p.f_rest) v *= 0.2f;
  }
  return cloud;
}

TEST(GltfSplats, TheGlbContainerIsLaidOutAsTheSpecSays) {
  io::GltfSplatOptions o;
  o.spz = false;
  o.classes = threeClasses();
  const auto glb = io::encodeSplatGlb("<test>", someSplats(), o);
  ASSERT_GE(glb.size(), 28u);
  EXPECT_EQ(wordAt(glb, 0), 0x46546c67u);  // "glTF"
  EXPECT_EQ(wordAt(glb, 4), 2u);
  EXPECT_EQ(wordAt(glb, 8), glb.size());
  const std::uint32_t json_length = wordAt(glb, 12);
  EXPECT_EQ(json_length % 4, 0u);
  EXPECT_EQ(wordAt(glb, 16), 0x4e4f534au);  // "JSON"
  const std::string text(glb.begin() + 20, glb.begin() + 20 + json_length);
  EXPECT_NE(text.find_last_not_of(' '), std::string::npos);
  const json gltf = json::parse(text);  // trailing padding is spaces
  const std::size_t bin_at = 20 + json_length;
  const std::uint32_t bin_length = wordAt(glb, bin_at);
  EXPECT_EQ(bin_length % 4, 0u);
  EXPECT_EQ(wordAt(glb, bin_at + 4), 0x004e4942u);  // "BIN\0"
  EXPECT_EQ(bin_at + 8 + bin_length, glb.size());
  EXPECT_EQ(gltf["buffers"][0]["byteLength"], bin_length);
  for (const auto& v : gltf["bufferViews"]) {
    EXPECT_EQ(v["byteOffset"].get<std::size_t>() % 8, 0u);
    EXPECT_LE(v["byteOffset"].get<std::size_t>() + v["byteLength"].get<std::size_t>(), bin_length);
  }
  const json& primitive = gltf["meshes"][0]["primitives"][0];
  EXPECT_EQ(primitive["mode"], 0);  // POINTS
  const json& a = primitive["attributes"];
  for (const char* name :
       {"POSITION", "COLOR_0", "KHR_gaussian_splatting:SCALE", "KHR_gaussian_splatting:ROTATION",
        "KHR_gaussian_splatting:OPACITY", "KHR_gaussian_splatting:SH_DEGREE_0_COEF_0",
        "KHR_gaussian_splatting:SH_DEGREE_3_COEF_6", "_FEATURE_ID_0"}) {
    ASSERT_TRUE(a.contains(name)) << name;
    EXPECT_EQ(gltf["accessors"][a[name].get<int>()]["count"], 50) << name;
  }
  const json& position = gltf["accessors"][a["POSITION"].get<int>()];
  EXPECT_EQ(position["min"].size(), 3u);
  EXPECT_EQ(primitive["extensions"]["KHR_gaussian_splatting"]["kernel"], "ellipse");
  EXPECT_EQ(primitive["extensions"]["KHR_gaussian_splatting"]["colorSpace"], "srgb_rec709_display");
  EXPECT_EQ(primitive["extensions"]["EXT_mesh_features"]["featureIds"][0]["nullFeatureId"], 65535);
  EXPECT_EQ(gltf["extensions"]["EXT_structural_metadata"]["propertyTables"][0]["count"], 3);
  EXPECT_FALSE(gltf.contains("extensionsRequired"));  // plain: a points renderer can fall back
}

TEST(GltfSplats, PlainAccessorsReadBackTheModel) {
  test::TempDir dir;
  const auto cloud = someSplats();
  io::GltfSplatOptions o;
  o.spz = false;
  o.classes = threeClasses();
  io::writeSplatGlb(dir.file("m.glb"), cloud, o);
  io::GltfSplatInfo info;
  const auto back = io::readSplatGlb(dir.file("m.glb"), &info);
  ASSERT_EQ(back.size(), cloud.size());
  EXPECT_FALSE(info.spz);
  EXPECT_EQ(info.sh_degree, 3);
  EXPECT_EQ(info.class_names, (std::vector<std::string>{"road", "building", "tree"}));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_EQ(back[i].x, cloud[i].x);
    EXPECT_EQ(back[i].z, cloud[i].z);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[i].scale[k], cloud[i].scale[k], 1e-5);
    EXPECT_EQ(back[i].f_dc[1], cloud[i].f_dc[1]);
    for (int k = 0; k < 45; ++k) EXPECT_EQ(back[i].f_rest[k], cloud[i].f_rest[k]);
    const float a = 1 / (1 + std::exp(-cloud[i].opacity));
    const float b = 1 / (1 + std::exp(-back[i].opacity));
    EXPECT_NEAR(a, b, 2e-3);  // logit clamped to half an 8-bit step from 0 and 1
    EXPECT_EQ(back[i].label, cloud[i].label);
    const float n = std::sqrt(cloud[i].rot[0] * cloud[i].rot[0] + cloud[i].rot[1] * cloud[i].rot[1] +
                              cloud[i].rot[2] * cloud[i].rot[2] + cloud[i].rot[3] * cloud[i].rot[3]);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(back[i].rot[k], cloud[i].rot[k] / n, 1e-6);
  }
}

TEST(GltfSplats, TheSpzPayloadKeepsTheGltfAxesWithinSpzQuantisation) {
  test::TempDir dir;
  const auto cloud = someSplats();
  io::GltfSplatOptions o;
  o.classes = threeClasses();
  io::writeSplatGlb(dir.file("m.glb"), cloud, o);
  const std::string bytes = test::readFile(dir.file("m.glb"));
  const json gltf = json::parse(bytes.substr(20, wordAt({bytes.begin(), bytes.end()}, 12)));
  EXPECT_EQ(gltf["extensionsRequired"],
            json::array({"KHR_gaussian_splatting", "KHR_gaussian_splatting_compression_spz_2"}));
  const json& a = gltf["meshes"][0]["primitives"][0]["attributes"];
  EXPECT_FALSE(gltf["accessors"][a["POSITION"].get<int>()].contains("bufferView"));
  EXPECT_TRUE(gltf["accessors"][a["_FEATURE_ID_0"].get<int>()].contains("bufferView"));
  io::GltfSplatInfo info;
  const auto back = io::readSplatGlb(dir.file("m.glb"), &info);
  EXPECT_TRUE(info.spz);
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_NEAR(back[i].x, cloud[i].x, 1.0 / 4096);  // not mirrored: the axes as stored
    EXPECT_NEAR(back[i].y, cloud[i].y, 1.0 / 4096);
    EXPECT_NEAR(back[i].z, cloud[i].z, 1.0 / 4096);
    EXPECT_NEAR(back[i].f_rest[0], cloud[i].f_rest[0], 1.0 / 16);
    EXPECT_EQ(back[i].label, cloud[i].label);
  }
}

TEST(GltfSplats, BadFilesAreRefusedByName) {
  test::TempDir dir;
  test::writeFile(dir.file("short.glb"), "glTF");
  EXPECT_THROW(io::readSplatGlb(dir.file("short.glb")), Error);
  io::GltfSplatOptions o;
  o.spz = false;
  auto glb = io::encodeSplatGlb("<test>", someSplats(), o);
  glb.resize(glb.size() - 16);  // truncated: the header's length no longer matches
  test::writeFile(dir.file("cut.glb"), std::string(glb.begin(), glb.end()));
  try {
    io::readSplatGlb(dir.file("cut.glb"));
    FAIL() << "a truncated file was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cut.glb"), std::string::npos);
  }
  // A container whose JSON lacks a field the reader needs: an Error naming the file, no crash.
  std::string text =
      R"({"meshes":[{"primitives":[{"attributes":{"POSITION":0},)"
      R"("extensions":{"KHR_gaussian_splatting":{}}}]}]})";
  while (text.size() % 4 != 0) text += ' ';
  std::string bare(20, '\0');
  const std::uint32_t header[5] = {0x46546c67u, 2, static_cast<std::uint32_t>(20 + text.size()),
                                   static_cast<std::uint32_t>(text.size()), 0x4e4f534au};
  std::memcpy(bare.data(), header, 20);
  test::writeFile(dir.file("bare.glb"), bare + text);
  try {
    io::readSplatGlb(dir.file("bare.glb"));
    FAIL() << "a glTF without accessors was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bare.glb"), std::string::npos) << e.what();
  }
  o.sh_degree = 4;
  EXPECT_THROW(io::encodeSplatGlb("<test>", someSplats(), o), Error);
  EXPECT_THROW(io::encodeSplatGlb("<test>", pcl::PointCloud<GaussianPoint>(), {}), Error);
}

}  // namespace
}  // namespace sadsplat
