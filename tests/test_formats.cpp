// Strand formats of the data sets and DCCs: PLY and USC-HairSalon .data round trips, their hostile
// files, unit and axis conversion, provenance of converted files, and the USD text hairgen writes.
#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

#include "libcore/io/hair_cache.h"
#include "libcore/io/hair_io.h"
#include "libcore/io/hairsalon_io.h"
#include "libcore/io/ply_io.h"
#include "libcore/io/usd_io.h"
#include "libcore/model/units.h"
#include "libcore/util/error.h"
#include "libcore/util/file_util.h"
#include "libcore/util/text.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

Strands decodePlyText(const std::string& text) {
  return decodePly(reinterpret_cast<const uint8_t*>(text.data()), text.size(), "t.ply");
}

// Everything PLY keeps, exactly, and the colours to 8 bits.
void expectSameThroughPly(const Strands& back, const Strands& s) {
  EXPECT_EQ(back.points, s.points);
  EXPECT_EQ(back.firstPoint, s.firstPoint);
  EXPECT_EQ(back.normals, s.normals);
  EXPECT_EQ(back.tangents, s.tangents);
  EXPECT_EQ(back.thickness, s.thickness);
  EXPECT_EQ(back.transparency, s.transparency);
  EXPECT_EQ(back.strandId, s.strandId);
  EXPECT_EQ(back.rootTriangle, s.rootTriangle);
  EXPECT_EQ(back.rootBary, s.rootBary);
  EXPECT_EQ(back.rootUv, s.rootUv);
  EXPECT_EQ(back.guideIds, s.guideIds);
  EXPECT_EQ(back.guideWeights, s.guideWeights);
  EXPECT_EQ(back.defaultThickness, s.defaultThickness);
  EXPECT_EQ(back.defaultColor, s.defaultColor);
  EXPECT_EQ(back.provenance, s.provenance);
  ASSERT_EQ(back.colors.size(), s.colors.size());
  for (size_t i = 0; i < s.colors.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.colors[i][c], s.colors[i][c], 0.5 / 255.0 + 1e-6);
}

TEST(Ply, BinaryRoundTripKeepsEveryPointBitForBit) {
  Strands s = test::sampleStrands(12, 4);
  std::vector<uint8_t> ply = encodePly(s, false);
  ASSERT_EQ(std::string(ply.begin(), ply.begin() + 36), "ply\nformat binary_little_endian 1.0\n");
  expectSameThroughPly(decodePly(ply.data(), ply.size(), "s.ply"), s);
}

TEST(Ply, AsciiRoundTripKeepsEveryPointBitForBit) {
  Strands s = test::sampleStrands(12, 5);
  s.points[3] = glm::vec3(1e-38f, -3.4028235e38f, 0.1f);  // extremes and a decimal that floats cannot hold
  std::vector<uint8_t> ply = encodePly(s, true);
  ASSERT_EQ(std::string(ply.begin(), ply.begin() + 21), "ply\nformat ascii 1.0\n");
  expectSameThroughPly(decodePly(ply.data(), ply.size(), "s.ply"), s);
}

TEST(Ply, HairToPlyToHairKeepsThePointsBitForBit) {
  test::TempDir dir("ply");
  Strands s = test::sampleStrands(30, 6);
  writeHair(dir / "a.hair", s);
  for (bool ascii : {false, true}) {
    writeStrands(dir / "a.ply", readStrands(dir / "a.hair"), WriteOptions{ascii});
    writeStrands(dir / "b.hair", readStrands(dir / "a.ply"));
    Strands back = readHair(dir / "b.hair");
    EXPECT_EQ(back.points, s.points) << (ascii ? "ascii" : "binary");
    EXPECT_EQ(back.firstPoint, s.firstPoint);
  }
}

TEST(Ply, EncodingIsDeterministic) {
  EXPECT_EQ(encodePly(test::sampleStrands(), false), encodePly(test::sampleStrands(), false));
}

TEST(Ply, StrandsFromEdgesAloneAndHairutilsLayout) {
  // Segment list only: two strands of 3 and 2 points, edges in any direction.
  Strands s = decodePlyText(
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element edge 3\nproperty int vertex1\nproperty int vertex2\nend_header\n"
      "0 0 0\n0 1 0\n0 2 0\n1 0 0\n1 1 0\n0 1\n2 1\n3 4\n");
  EXPECT_EQ(s.firstPoint, (std::vector<uint32_t>{0, 3, 5}));
  EXPECT_EQ(s.points[4], glm::vec3(1, 1, 0));
  EXPECT_FALSE(s.provenance.metres);  // a file made elsewhere: its own units
  // hairutil's layout: a strand element with nsegs, uchar colours, a redundant edge list, CRLF lines.
  s = decodePlyText(
      "ply\r\nformat ascii 1.0\r\ncomment Written with hapPLY\r\nelement vertex 3\r\nproperty float x\r\n"
      "property float y\r\nproperty float z\r\nproperty uchar red\r\nproperty uchar green\r\nproperty uchar "
      "blue\r\nelement strand 1\r\nproperty ushort nsegs\r\nelement edge 2\r\nproperty int vertex1\r\n"
      "property int vertex2\r\nend_header\r\n1 2 3 255 0 51\r\n4 5 6 255 0 51\r\n7 8 9 255 0 51\r\n2\r\n0 "
      "1\r\n"
      "1 2\r\n");
  EXPECT_EQ(s.firstPoint, (std::vector<uint32_t>{0, 3}));
  EXPECT_EQ(s.colors[0], glm::vec3(1.0f, 0.0f, 0.2f));
  EXPECT_EQ(s.provenance.sourceInfo, "Written with hapPLY");
  // vertex_count counts points; a double x is rounded to float.
  s = decodePlyText(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\n"
      "element strand 1\nproperty int vertex_count\nend_header\n0.1 0 0\n0 0 0.25\n2\n");
  EXPECT_EQ(s.points[0].x, 0.1f);
}

TEST(Ply, BigEndianIsRead) {
  std::string text =
      "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nelement strand 1\nproperty ushort nsegs\nend_header\n";
  for (float v : {1.0f, 2.0f, 3.0f, -4.0f, 5.5f, 6.0f}) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    for (int i = 3; i >= 0; --i) text += char(bits >> (8 * i));
  }
  text += std::string("\0\1", 2);
  Strands s = decodePlyText(text);
  EXPECT_EQ(s.points[1], glm::vec3(-4.0f, 5.5f, 6.0f));
}

TEST(Ply, HostileFilesAreInputErrors) {
  const std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex ";
  const std::string props =
      "\nproperty float x\nproperty float y\nproperty float z\nelement strand 1\n"
      "property ushort nsegs\nend_header\n";
  for (const char* count : {"18446744073709551615", "1000000000000", "4"})  // more than the bytes hold
    EXPECT_THROW(decodePlyText(head + count + props + std::string(14, '\0')), InputError) << count;
  EXPECT_THROW(decodePlyText("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                             "end_header\n0 0 0\n3 0 0 0\n"),
               InputError);  // a mesh
  EXPECT_THROW(decodePlyText("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "property float z\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n"
                             "end_header\n0 0 0\n1 0 0\n2 0 0\n0 2\n"),
               InputError);  // an edge that skips a vertex
  EXPECT_THROW(decodePlyText("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                             "property float z\nelement strand 1\nproperty uchar nsegs\nend_header\n"
                             "nan 0 0\n0 0 0\n1\n"),
               InputError);  // not finite
  EXPECT_THROW(decodePlyText("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                             "property float z\nelement strand 1\nproperty uchar nsegs\nend_header\n"
                             "0 0 0\n0 0 0\n5\n"),
               InputError);  // counts past the vertices
  EXPECT_THROW(decodePlyText("ply\nformat ascii 1.0\nelement vertex 1\nproperty list uint float x\n"
                             "end_header\n4000000000 1\n"),
               InputError);  // x is a list; and the list's length is absurd
  try {                      // a tangent component as a list: refused, not left unread
    decodePlyText(
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nproperty list uchar float tangent_x\nproperty float tangent_y\n"
        "property float tangent_z\nelement strand 1\nproperty uchar nsegs\nend_header\n"
        "0 0 0 1 1 0 0\n0 1 0 1 1 0 0\n1\n");
    ADD_FAILURE() << "a list tangent_x was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'tangent_x' is a list"), std::string::npos) << e.what();
  }
  EXPECT_THROW(decodePlyText("ply\nformat ascii 2.0\nend_header\n"), InputError);
  EXPECT_THROW(decodePlyText("plyx"), InputError);
}

TEST(Ply, EveryTruncationIsAnInputError) {
  std::vector<uint8_t> ply = encodePly(test::sampleStrands(3), false);
  for (size_t length = 0; length < ply.size(); ++length)
    EXPECT_THROW(decodePly(ply.data(), length, "t.ply"), InputError) << "length " << length;
}

TEST(Ply, ErrorsNameTheFile) {
  try {
    decodePly(reinterpret_cast<const uint8_t*>("ply\n"), 4, "named.ply");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("named.ply", 0), 0u) << e.what();
  }
}

TEST(HairSalon, RoundTripKeepsEveryPointBitForBit) {
  Strands s = test::sampleStrands(20, 7);
  std::vector<uint8_t> data = encodeHairSalon(s);
  EXPECT_EQ(data.size(), 4 + 4 * s.strandCount() + 12 * s.pointCount());
  Strands back = decodeHairSalon(data.data(), data.size(), "s.data");
  EXPECT_EQ(back.points, s.points);
  EXPECT_EQ(back.firstPoint, s.firstPoint);
  EXPECT_FALSE(back.provenance.metres);  // the layout has no header to say
  EXPECT_EQ(encodeHairSalon(back), data);
}

TEST(HairSalon, HostileFilesAreInputErrors) {
  std::vector<uint8_t> data = encodeHairSalon(test::sampleStrands(4));
  for (size_t length = 0; length < data.size(); ++length)
    EXPECT_THROW(decodeHairSalon(data.data(), length, "t.data"), InputError) << "length " << length;
  for (int32_t count : {-1, INT32_MAX, 1 << 28}) {
    std::vector<uint8_t> bad = data;
    std::memcpy(bad.data(), &count, 4);  // strands
    EXPECT_THROW(decodeHairSalon(bad.data(), bad.size(), "t.data"), InputError);
    bad = data;
    std::memcpy(bad.data() + 4, &count, 4);  // the first strand's points
    EXPECT_THROW(decodeHairSalon(bad.data(), bad.size(), "t.data"), InputError);
  }
  data.push_back(0);
  EXPECT_THROW(decodeHairSalon(data.data(), data.size(), "t.data"), InputError);
}

TEST(Units, NamesAndFactors) {
  EXPECT_EQ(parseLengthUnit("mm"), 0.001);
  EXPECT_EQ(parseLengthUnit("CM"), 0.01);
  EXPECT_EQ(parseLengthUnit("in"), 0.0254);
  EXPECT_EQ(parseLengthUnit("0.5"), 0.5);
  for (const char* bad : {"", "km", "0", "-1", "nan", "inf", "1e400"})
    EXPECT_FALSE(parseLengthUnit(bad)) << bad;
  EXPECT_EQ(parseUpAxis("Z"), UpAxis::kZ);
  EXPECT_FALSE(parseUpAxis("x"));
}

TEST(Units, ZUpMillimetresBecomeYUpMetresAndSaySo) {
  Strands s;
  s.addStrand({glm::vec3(0, 0, 0), glm::vec3(10, 20, 30)});
  s.thickness = {0.07f, 0.07f};
  s.tangents = {glm::vec3(0, 0, 1), glm::vec3(0, 0, 1)};
  s.provenance.metres = s.provenance.yUp = false;
  convertToHairgenFrame(s, UnitConversion{0.001, UpAxis::kZ});
  EXPECT_EQ(s.points[1], glm::vec3(10.0f, 30.0f, -20.0f) * 0.001f);
  EXPECT_EQ(s.tangents[0], glm::vec3(0, 1, 0));  // +z up is +y up
  EXPECT_FLOAT_EQ(s.thickness[0], 7e-5f);
  EXPECT_TRUE(s.provenance.metres && s.provenance.yUp);
  EXPECT_EQ(s.provenance.conversion, "units mm (x0.001); up axis z turned to +y");
  // Only a unit: the axis stays unknown.
  Strands t;
  t.addStrand({glm::vec3(1, 2, 3)});
  t.provenance.metres = t.provenance.yUp = false;
  convertToHairgenFrame(t, UnitConversion{0.01, std::nullopt});
  EXPECT_TRUE(t.provenance.metres);
  EXPECT_FALSE(t.provenance.yUp);
}

std::string usdaOf(const Strands& s) {
  std::ostringstream out;
  encodeUsda(out, s);
  return out.str();
}

TEST(Usd, OneLinearBasisCurvesPrimWithWhatHairgenKnows) {
  Strands s = test::sampleStrands(4, 8);
  const std::string usda = usdaOf(s);
  EXPECT_EQ(usda.rfind("#usda 1.0\n", 0), 0u);
  for (const char* want :
       {"defaultPrim = \"hair\"", "metersPerUnit = 1", "upAxis = \"Y\"", "def BasisCurves \"hair\"",
        "uniform token type = \"linear\"", "int[] curveVertexCounts = [2,5,8,2]", "point3f[] points = [",
        "float[] widths = [", "normal3f[] primvars:hairgen:volumeNormal = [",
        "color3f[] primvars:displayColor = [",
        "int[] primvars:groom_id = [1000,1001,1002,1003] (\n        interpolation = \"uniform\"",
        "int primvars:groom_guide = 0 (", "float2[] primvars:groom_root_uv",
        "int3[] primvars:groom_closest_guides = [(0,1,2),(1,2,3)", "float3[] primvars:groom_guide_weights",
        "string configDigest = \"0123456789abcdef\""})
    EXPECT_NE(usda.find(want), std::string::npos) << want;
  // Volume normals are a hairgen primvar: `normals` would make USD draw the curves as ribbons.
  EXPECT_EQ(usda.find(" normals = "), std::string::npos);
  // The widths are the diameters, one per vertex, in their shortest exact form.
  const size_t widths = usda.find("float[] widths = [");
  EXPECT_EQ(usda.substr(widths + 18, formatFloat(s.thickness[0]).size()), formatFloat(s.thickness[0]));
  EXPECT_NE(usda.find("interpolation = \"vertex\"", widths), std::string::npos);
  // What grow or simulate made is guides.
  s.provenance.stage = "simulate";
  EXPECT_NE(usdaOf(s).find("int primvars:groom_guide = 1 ("), std::string::npos);
}

// The numbers of the array that follows `key`, as floats, in order.
std::vector<float> floatsAfter(const std::string& text, const std::string& key) {
  size_t at = text.find('[', text.find(key) + key.size()) + 1;
  const size_t end = text.find(']', at);
  std::vector<float> out;
  while (at < end) {
    while (at < end && std::string("(),\n ").find(text[at]) != std::string::npos) ++at;
    if (at >= end) break;
    size_t used = 0;
    out.push_back(std::stof(text.substr(at, 40), &used));
    at += used;
  }
  return out;
}

TEST(Usd, ExtentIsThePointsBoxGrownByHalfTheWidestWidth) {
  Strands s;
  s.addStrand({glm::vec3(0, 0, 0), glm::vec3(1, 2, 3)});
  s.thickness = {0.1f, 0.3f};
  const std::vector<float> extent = floatsAfter(usdaOf(s), "float3[] extent");
  ASSERT_EQ(extent.size(), 6u);
  const float pad = 0.3f * 0.5f;
  EXPECT_EQ(extent, (std::vector<float>{-pad, -pad, -pad, 1 + pad, 2 + pad, 3 + pad}));
}

TEST(Usd, UnknownUnitsAreNotClaimedAndOnePointStrandsAreLeftOut) {
  Strands s;
  s.addStrand({glm::vec3(0), glm::vec3(1)});
  s.provenance.metres = s.provenance.yUp = false;
  const std::string usda = usdaOf(s);
  EXPECT_EQ(usda.find("metersPerUnit"), std::string::npos);
  EXPECT_EQ(usda.find("upAxis"), std::string::npos);
  EXPECT_NE(usda.find("float[] widths = [7e-05] (\n        interpolation = \"constant\""), std::string::npos);
  // A bare follicle (USC-HairSalon's one-point strand) is no linear curve: left out and counted.
  s.addStrand({glm::vec3(2)});
  s.addStrand({glm::vec3(3), glm::vec3(4), glm::vec3(5)});
  s.strandId = {7, 8, 9};
  std::ostringstream out;
  EXPECT_EQ(encodeUsda(out, s).droppedStrands, 1u);
  EXPECT_NE(out.str().find("int[] curveVertexCounts = [2,3]"), std::string::npos);
  EXPECT_NE(out.str().find("int[] primvars:groom_id = [7,9]"), std::string::npos);
  EXPECT_EQ(floatsAfter(out.str(), "point3f[] points").size(), 15u);
  Strands bare;
  bare.addStrand({glm::vec3(2)});
  EXPECT_THROW(usdaOf(bare), InputError);  // nothing left to write
  Strands ids = test::sampleStrands(2);
  ids.strandId[1] = 1u << 31;
  EXPECT_THROW(usdaOf(ids), InputError);
}

// A shot of `frames` frames of sampleStrands moving along +x by 0.5 m a frame, simulated at 25 fps.
UsdShotPrim movingPrim(int firstFrame, const std::string& stage) {
  return UsdShotPrim{[firstFrame, stage](int f) {
                       Strands s = test::sampleStrands(3);
                       s.provenance.stage = stage;
                       s.provenance.frame = f;
                       s.provenance.time = (f - firstFrame) / 25.0;
                       for (glm::vec3& p : s.points) p.x += 0.5f * float(f);
                       return s;
                     },
                     "moving.####.hair"};
}

TEST(Usd, AShotTimeSamplesWhatMovesAtTheCachesFrameRate) {
  test::TempDir dir("usdshot");
  UsdShot shot;
  shot.frames = {3, 5};
  shot.strands = movingPrim(1, "interpolate");
  shot.guides = movingPrim(1, "simulate");
  EXPECT_EQ(writeUsdShot(dir / "shot.usda", shot).droppedStrands, 0u);
  const std::string usda = readFileText(dir / "shot.usda");
  for (const char* want : {"startTimeCode = 3\n", "endTimeCode = 5\n", "timeCodesPerSecond = 25\n",
                           "def Xform \"hair\"", "def BasisCurves \"strands\"", "def BasisCurves \"guides\"",
                           "point3f[] points.timeSamples = {\n            3: [",
                           "float3[] extent.timeSamples", "int primvars:groom_guide = 1"})
    EXPECT_NE(usda.find(want), std::string::npos) << want;
  // Frame 4's points are the cache's, to the float.
  Strands four = shot.strands->frame(4);
  const std::vector<float> sample = floatsAfter(usda, "            4: ");
  ASSERT_EQ(sample.size(), 3 * four.pointCount());
  for (size_t i = 0; i < four.pointCount(); ++i) EXPECT_EQ(sample[3 * i], four.points[i].x);
  // What does not move is written once.
  EXPECT_EQ(usda.find("widths.timeSamples"), std::string::npos);
  EXPECT_EQ(usda.find("volumeNormal.timeSamples"), std::string::npos);
}

TEST(Usd, AShotRefusesFramesOfOtherStrandsAndCachesWithoutTheirTime) {
  test::TempDir dir("usdshot");
  UsdShot shot;
  shot.frames = {1, 3};
  shot.strands = movingPrim(1, "interpolate");
  auto frame = shot.strands->frame;
  shot.strands->frame = [frame](int f) {
    Strands s = frame(f);
    if (f == 3) s.strandId[0] = 5;
    return s;
  };
  try {
    writeUsdShot(dir / "shot.usda", shot);
    ADD_FAILURE() << "frame 3's other strands were written";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, "moving.0003.hair");
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "shot.usda"));
  shot.strands = movingPrim(1, "interpolate");
  shot.strands->frame = [frame](int f) {
    Strands s = frame(f);
    s.provenance.frame.reset();
    return s;
  };
  EXPECT_THROW(writeUsdShot(dir / "shot.usda", shot), InputError);
  shot.framesPerSecond = 30.0;  // given, it needs no frame times
  writeUsdShot(dir / "shot.usda", shot);
  EXPECT_NE(readFileText(dir / "shot.usda").find("timeCodesPerSecond = 30\n"), std::string::npos);
}

// The one table of formats says which are read; readStrands must read exactly those, and the list the
// commands print for their inputs must name exactly those.
TEST(Formats, ReadStrandsReadsExactlyTheFormatsListedAsRead) {
  test::TempDir dir("formats");
  const Strands s = test::sampleStrands(3);
  std::string readable;
  std::istringstream known(hairExtensionList());
  for (std::string ext; known >> ext;) {
    if (ext.back() == ',') ext.pop_back();
    const std::filesystem::path file = dir / ("s" + ext);
    writeStrands(file, s);
    if (hairgenReads(hairFormatOf(file))) {
      EXPECT_EQ(readStrands(file).strandCount(), s.strandCount()) << ext;
      readable += (readable.empty() ? "" : ", ") + ext;
    } else {
      EXPECT_THROW(readStrands(file), InputError) << ext;
    }
  }
  EXPECT_EQ(readHairExtensionList(), readable);
  EXPECT_EQ(readable.find(".usda"), std::string::npos);  // USD is export only (DESIGN §6)
}

TEST(Provenance, AConvertedFileSaysWhereItCameFromThroughEveryFormat) {
  test::TempDir dir("prov");
  const std::vector<uint8_t> data = encodeHairSalon(test::sampleStrands(3));
  writeFileAtomic(dir / "in.data", data.data(), data.size());
  Strands s = readStrands(dir / "in.data", UnitConversion{0.01, UpAxis::kY});
  EXPECT_EQ(s.provenance.source, "in.data");
  EXPECT_EQ(s.provenance.conversion, "units cm (x0.01); up axis y kept");
  EXPECT_EQ(s.defaultThickness, Strands{}.defaultThickness);  // .data states none: hairgen's, in metres
  s.provenance.producer = "hairgen test";
  s.provenance.stage = "convert";
  for (const char* name : {"out.hair", "out.ply", "out.glb"}) {
    writeStrands(dir / name, s);
    EXPECT_EQ(readStrands(dir / name).provenance, s.provenance) << name;
  }
  // Unknown units survive as unknown.
  Strands unknown = readStrands(dir / "in.data");
  unknown.provenance.producer = "hairgen test";
  writeStrands(dir / "u.hair", unknown);
  EXPECT_FALSE(readStrands(dir / "u.hair").provenance.metres);
}

}  // namespace
}  // namespace hairgen
