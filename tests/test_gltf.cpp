// glTF caches: round trips through .glb and .gltf, and files hairgen must refuse.
#include <gtest/gtest.h>

#include <cstring>

#include <nlohmann/json.hpp>

#include "libcore/io/gltf_io.h"
#include "libcore/io/hair_io.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

TEST(Gltf, GlbRoundTripKeepsEveryAttribute) {
  Strands s = test::sampleStrands();
  std::vector<uint8_t> glb = encodeGltf(s, true);
  ASSERT_EQ(std::string(glb.begin(), glb.begin() + 4), "glTF");
  test::expectSameStrands(decodeGltf(glb.data(), glb.size(), "s.glb"), s);
}

TEST(Gltf, GltfJsonRoundTripKeepsEveryAttribute) {
  Strands s = test::sampleStrands(9, 3);
  std::vector<uint8_t> json = encodeGltf(s, false);
  EXPECT_EQ(json.front(), '{');
  test::expectSameStrands(decodeGltf(json.data(), json.size(), "s.gltf"), s);
}

TEST(Gltf, ColoursAboveOneAreClampedInColor0AndKeptInTheirOwnAttribute) {
  Strands s = test::sampleStrands(4, 3);
  for (size_t i = 0; i < s.colors.size(); ++i)
    s.colors[i] = glm::vec3(0.2f + 0.5f * float(i % 4));  // up to 1.7
  std::vector<uint8_t> json = encodeGltf(s, false);
  const std::string text(json.begin(), json.end());
  EXPECT_NE(text.find("\"_COLOR\""), std::string::npos);
  test::expectSameStrands(decodeGltf(json.data(), json.size(), "s.gltf"), s);  // the values themselves
  Strands inRange = test::sampleStrands(4, 3);
  json = encodeGltf(inRange, false);
  EXPECT_EQ(std::string(json.begin(), json.end()).find("\"_COLOR\""), std::string::npos);
}

TEST(Gltf, EncodingIsDeterministic) {
  EXPECT_EQ(encodeGltf(test::sampleStrands(), true), encodeGltf(test::sampleStrands(), true));
}

TEST(Gltf, HairToGlbToHairGivesTheSamePoints) {
  Strands s = test::sampleStrands(20, 9);
  std::vector<uint8_t> glb = encodeGltf(s, true);
  Strands back = decodeGltf(glb.data(), glb.size(), "x.glb");
  EXPECT_EQ(back.points, s.points);
  EXPECT_EQ(back.firstPoint, s.firstPoint);
  if (!std::filesystem::exists(test::realData())) return;
  Strands straight = readHair(test::realData() / "luxcore" / "straight.hair");
  glb = encodeGltf(straight, true);
  back = decodeGltf(glb.data(), glb.size(), "straight.glb");
  EXPECT_EQ(back.points, straight.points);
  EXPECT_EQ(back.firstPoint, straight.firstPoint);
  EXPECT_EQ(back.colors, straight.colors);
}

TEST(Gltf, AccessorPastItsBufferIsRejected) {
  std::vector<uint8_t> json = encodeGltf(test::sampleStrands(2), false);
  std::string text(json.begin(), json.end());
  size_t at = text.find("\"count\"");
  ASSERT_NE(at, std::string::npos);
  size_t digits = text.find_first_of("0123456789", at);
  size_t end = text.find_first_not_of("0123456789", digits);
  text.replace(digits, end - digits, "99999");
  EXPECT_THROW(decodeGltf(reinterpret_cast<const uint8_t*>(text.data()), text.size(), "bad.gltf"),
               InputError);
}

TEST(Gltf, GarbageIsAnInputError) {
  std::string junk = "{ not json";
  EXPECT_THROW(decodeGltf(reinterpret_cast<const uint8_t*>(junk.data()), junk.size(), "j.gltf"), InputError);
  std::vector<uint8_t> glb = encodeGltf(test::sampleStrands(2), true);
  glb.resize(glb.size() / 2);
  EXPECT_THROW(decodeGltf(glb.data(), glb.size(), "half.glb"), InputError);
}

TEST(Gltf, AnExternalBufferBesideAFileNamedWithoutAFolderIsRead) {
  // x.gltf names its buffer x.bin; read as "x.gltf" from its own folder, its folder is ".", not none.
  const std::vector<uint8_t> glb = encodeGltf(test::sampleStrands(3), true);
  uint32_t jsonLength, binLength;
  std::memcpy(&jsonLength, glb.data() + 12, 4);
  std::memcpy(&binLength, glb.data() + 20 + jsonLength, 4);
  nlohmann::json json = nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + jsonLength);
  json["buffers"][0]["uri"] = "x.bin";
  test::TempDir dir("gltf-external");
  writeFileAtomic(dir / "x.gltf", json.dump());
  const uint8_t* bin = glb.data() + 28 + jsonLength;
  writeFileAtomic(dir / "x.bin", bin, binLength);
  const std::filesystem::path before = std::filesystem::current_path();
  std::filesystem::current_path(dir.path());
  Strands read;
  EXPECT_NO_THROW(read = readGltf("x.gltf"));
  std::filesystem::current_path(before);
  EXPECT_EQ(read.points, test::sampleStrands(3).points);
}

// The JSON of a .glb.
nlohmann::json glbJson(const std::vector<uint8_t>& glb) {
  uint32_t length;
  std::memcpy(&length, glb.data() + 12, 4);
  return nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + length);
}

TEST(Gltf, PerStrandValuesAreStoredOncePerStrandAndIndexedFromEachVertex) {
  const Strands s = test::sampleStrands(30, 5);
  const std::vector<uint8_t> glb = encodeGltf(s, true);
  const nlohmann::json json = glbJson(glb);
  const nlohmann::json& primitive = json["meshes"][0]["primitives"][0];
  for (const char* key :
       {"_STRAND_ID", "_ROOT_UV", "_GUIDE_IDS", "_GUIDE_WEIGHTS", "_ROOT_TRIANGLE", "_ROOT_BARY"}) {
    EXPECT_FALSE(primitive["attributes"].contains(key)) << key << " is repeated on every vertex";
    ASSERT_TRUE(primitive["extras"]["perStrand"].contains(key)) << key;
    EXPECT_EQ(json["accessors"][primitive["extras"]["perStrand"][key].get<int>()]["count"], s.strandCount())
        << key;
  }
  // _STRAND: vertex v's strand, the index into those accessors.
  const nlohmann::json& strandOf = json["accessors"][primitive["attributes"]["_STRAND"].get<int>()];
  ASSERT_EQ(strandOf["count"], s.pointCount());
  const nlohmann::json& view = json["bufferViews"][strandOf["bufferView"].get<int>()];
  uint32_t jsonLength;
  std::memcpy(&jsonLength, glb.data() + 12, 4);
  const uint8_t* bin = glb.data() + 28 + jsonLength;
  for (size_t i = 0; i < s.strandCount(); ++i)
    for (uint32_t p = s.firstPoint[i]; p < s.firstPoint[i + 1]; ++p) {
      float k;
      std::memcpy(&k, bin + view["byteOffset"].get<size_t>() + 4 * p, 4);
      ASSERT_EQ(k, float(i)) << "vertex " << p;
    }
}

TEST(Gltf, IdsPast2To24RoundTripNowThatTheyAreNotVertexAttributes) {
  Strands s = test::sampleStrands(3);
  s.strandId[1] = 4000000123u;
  s.guideIds[2] = glm::uvec3(1u << 30, 7, (1u << 24) + 1);
  s.rootTriangle[0] = (1u << 24) + 3;
  const std::vector<uint8_t> glb = encodeGltf(s, true);
  test::expectSameStrands(decodeGltf(glb.data(), glb.size(), "big.glb"), s);
}

TEST(Gltf, OnePointStrandsAreDroppedNotLeftAsLooseVertices) {
  // A USC-HairSalon style's bare follicles: a loose vertex would be joined to the strand before it by
  // readers that take runs of vertices as strands.
  Strands s;
  s.addStrand({glm::vec3(0, 0, 0), glm::vec3(0, -0.01f, 0)});
  s.addStrand({glm::vec3(1, 0, 0)});
  s.addStrand({glm::vec3(2, 0, 0), glm::vec3(2, -0.01f, 0), glm::vec3(2, -0.02f, 0)});
  s.addStrand({glm::vec3(3, 0, 0)});
  s.strandId = {10, 11, 12, 13};
  size_t dropped = 0;
  const std::vector<uint8_t> glb = encodeGltf(s, true, &dropped);
  EXPECT_EQ(dropped, 2u);
  const nlohmann::json json = glbJson(glb);
  EXPECT_EQ(
      json["accessors"][json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<int>()]["count"], 5);
  EXPECT_EQ(json["asset"]["extras"]["onePointStrandsDropped"], 2);
  const Strands back = decodeGltf(glb.data(), glb.size(), "follicles.glb");
  ASSERT_EQ(back.strandCount(), 2u);
  EXPECT_EQ(back.firstPoint, (std::vector<uint32_t>{0, 2, 5}));
  EXPECT_EQ(back.points[2], glm::vec3(2, 0, 0));
  EXPECT_EQ(back.strandId, (std::vector<uint32_t>{10, 12}));
  Strands follicles;
  follicles.addStrand({glm::vec3(0.0f)});
  EXPECT_THROW(encodeGltf(follicles, true), InputError);  // nothing left to write
}

TEST(Gltf, FilesOfEarlierHairgenWithValuesOnEveryVertexAreRead) {
  // The layout before per-strand accessors: _STRAND_ID etc. as FLOAT attributes on every vertex.
  Strands s = test::sampleStrands(4, 2);
  std::vector<uint8_t> glb = encodeGltf(s, true);
  nlohmann::json json = glbJson(glb);
  uint32_t jsonLength, binLength;
  std::memcpy(&jsonLength, glb.data() + 12, 4);
  std::memcpy(&binLength, glb.data() + 20 + jsonLength, 4);
  std::vector<uint8_t> bin(glb.begin() + 28 + jsonLength, glb.begin() + 28 + jsonLength + binLength);
  nlohmann::json& primitive = json["meshes"][0]["primitives"][0];
  auto append = [&](const std::vector<float>& values, const char* type) {
    json["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", 4 * values.size()}});
    const uint8_t* bytes = reinterpret_cast<const uint8_t*>(values.data());
    bin.insert(bin.end(), bytes, bytes + 4 * values.size());
    json["accessors"].push_back({{"bufferView", json["bufferViews"].size() - 1},
                                 {"componentType", 5126},
                                 {"count", s.pointCount()},
                                 {"type", type}});
    return json["accessors"].size() - 1;
  };
  std::vector<float> ids, uvs;
  for (size_t i = 0; i < s.strandCount(); ++i)
    for (uint32_t p = s.firstPoint[i]; p < s.firstPoint[i + 1]; ++p) {
      ids.push_back(float(s.strandId[i]));
      uvs.insert(uvs.end(), {s.rootUv[i].x, s.rootUv[i].y});
    }
  primitive["attributes"]["_STRAND_ID"] = append(ids, "SCALAR");
  primitive["attributes"]["_ROOT_UV"] = append(uvs, "VEC2");
  primitive["extras"]["perStrand"].erase("_STRAND_ID");
  primitive["extras"]["perStrand"].erase("_ROOT_UV");
  json["buffers"][0]["byteLength"] = bin.size();
  const std::string bytes = "data:application/octet-stream;base64,";
  std::string encoded;
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (size_t i = 0; i < bin.size(); i += 3) {
    const uint32_t v = uint32_t(bin[i]) << 16 | (i + 1 < bin.size() ? uint32_t(bin[i + 1]) << 8 : 0u) |
                       (i + 2 < bin.size() ? bin[i + 2] : 0u);
    encoded += kAlphabet[v >> 18 & 63];
    encoded += kAlphabet[v >> 12 & 63];
    encoded += i + 1 < bin.size() ? kAlphabet[v >> 6 & 63] : '=';
    encoded += i + 2 < bin.size() ? kAlphabet[v & 63] : '=';
  }
  json["buffers"][0]["uri"] = bytes + encoded;
  const std::string text = json.dump();
  test::expectSameStrands(decodeGltf(reinterpret_cast<const uint8_t*>(text.data()), text.size(), "old.gltf"),
                          s);
}

TEST(Gltf, EmptyStrandsCannotBeWritten) {
  Strands empty;
  EXPECT_THROW(encodeGltf(empty, true), InputError);
}

}  // namespace
}  // namespace hairgen
