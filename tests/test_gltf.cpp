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

TEST(Gltf, EmptyStrandsCannotBeWritten) {
  Strands empty;
  EXPECT_THROW(encodeGltf(empty, true), InputError);
}

}  // namespace
}  // namespace hairgen
