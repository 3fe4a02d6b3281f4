// OBJ reading: polygons, normals indexed apart, missing normals, degenerate faces, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "libcore/io/obj_io.h"
#include "libcore/util/error.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

const char* kQuad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

TEST(Obj, QuadsAreTriangulated) {
  MeshReadStats stats;
  Mesh m = parseObj(kQuad, "quad.obj", &stats);
  EXPECT_EQ(m.vertexCount(), 4u);
  EXPECT_EQ(m.triangleCount(), 2u);
  EXPECT_EQ(stats.polygonsTriangulated, 1u);
  EXPECT_NEAR(surfaceArea(m), 1.0, 1e-9);
}

TEST(Obj, MissingNormalsAreComputedAreaWeighted) {
  // Two triangles sharing vertex 0: a big one in the xy plane and a small one in the xz plane.
  MeshReadStats stats;
  Mesh m = parseObj("v 0 0 0\nv 2 0 0\nv 0 2 0\nv 0 0 -0.1\nf 1 2 3\nf 1 4 2\n", "a.obj", &stats);
  EXPECT_FALSE(stats.normalsFromFile);
  glm::vec3 expected = glm::normalize(glm::vec3(0, 0, 4) + glm::vec3(0, -0.2f, 0));  // 2 × area each
  EXPECT_NEAR(glm::length(m.normals[0] - expected), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(m.normals[2] - glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
}

TEST(Obj, NormalsIndexedApartAreAveragedPerPosition) {
  // A hard edge: vertex 2 and 3 are shared by faces with different normals, given per corner.
  MeshReadStats stats;
  Mesh m = parseObj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1\nvn 0 0 1\nvn 0 -1 1\n"
      "f 1//1 2//1 3//1\nf 1//2 3//2 4//2\n",
      "n.obj", &stats);
  EXPECT_TRUE(stats.normalsFromFile);
  EXPECT_TRUE(stats.normalsReindexed);
  EXPECT_EQ(m.vertexCount(), 4u);  // one follicle per position, not per corner
  EXPECT_NEAR(glm::length(m.normals[1] - glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
  glm::vec3 averaged = glm::normalize(glm::vec3(0, 0, 1) + glm::normalize(glm::vec3(0, -1, 1)));
  EXPECT_NEAR(glm::length(m.normals[0] - averaged), 0.0f, 1e-6f);
}

TEST(Obj, DegenerateFacesAreDroppedAndCounted) {
  MeshReadStats stats;
  Mesh m = parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\nf 1 2 4\n", "d.obj", &stats);
  EXPECT_EQ(m.triangleCount(), 1u);
  EXPECT_EQ(stats.degenerateDropped, 2u);  // a repeated corner; three collinear points
  EXPECT_EQ(stats.unreferencedDropped, 1u);
  EXPECT_EQ(m.vertexCount(), 3u);
}

TEST(Obj, EmptyMeshesAreErrors) {
  EXPECT_THROW(parseObj("# nothing\n", "e.obj"), InputError);
  EXPECT_THROW(parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "p.obj"), InputError);           // points, no faces
  EXPECT_THROW(parseObj("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "l.obj"), InputError);  // all degenerate
}

// A polygon is triangulated in time that grows with the square of its corners (200,000 corners: minutes):
// 256 corners read, 257 are refused naming the line.
TEST(Obj, APolygonOfThousandsOfCornersIsRefused) {
  auto polygon = [](int corners) {
    std::ostringstream obj;
    for (int i = 0; i < corners; ++i)
      obj << "v " << std::cos(2.0 * M_PI * i / corners) << " " << std::sin(2.0 * M_PI * i / corners)
          << " 0\n";
    obj << "f";
    for (int i = 1; i <= corners; ++i) obj << " " << i;
    obj << "\n";
    return obj.str();
  };
  EXPECT_EQ(parseObj(polygon(256), "fan.obj").triangleCount(), 254u);
  try {
    parseObj(polygon(257), "fan.obj");
    ADD_FAILURE() << "a face of 257 corners was read";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("fan.obj:258: a face of 257 corners", 0), 0u) << e.what();
  }
}

TEST(Obj, BadNumbersAndIndicesNameTheLine) {
  auto message = [](const char* obj) {
    try {
      parseObj(obj, "bad.obj");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("v 0 0 0\nv 1 0 x\n").rfind("bad.obj:2:", 0), 0u);
  EXPECT_EQ(message("v 0 0 0\nv 1 0 nan\n").rfind("bad.obj:2:", 0), 0u);
  EXPECT_EQ(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").rfind("bad.obj:4:", 0), 0u);
  EXPECT_EQ(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n").rfind("bad.obj:4:", 0), 0u);
  EXPECT_EQ(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n").rfind("bad.obj:4:", 0), 0u);
  EXPECT_EQ(message("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//2 2 3\n").rfind("bad.obj:4:", 0), 0u);
}

TEST(Obj, StatementsHairgenDoesNotReadChangeNothing) {
  // Objects, groups, materials, lines, skin weights and tags never reach tinyobjloader, whose parser
  // converted this 'vw' joint id of 7.8e32 to int (undefined behaviour; tests/fuzz found it).
  const Mesh plain = parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "plain.obj");
  const Mesh extra = parseObj(
      "mtllib m.mtl\no head\ng scalp\nusemtl skin\ns 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n"
      "vw 0 777777777777777777777777777777777 1\nt crease 2/1/0 1 2 3.5\nf 1 2 3\n",
      "extra.obj");
  EXPECT_EQ(extra.positions, plain.positions);
  EXPECT_EQ(extra.normals, plain.normals);
  EXPECT_EQ(extra.triangles, plain.triangles);
}

TEST(Obj, NegativeIndicesCountBack) {
  Mesh m = parseObj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n", "neg.obj");
  EXPECT_EQ(m.triangleCount(), 1u);
}

TEST(Obj, WrittenMeshReadsBackIdentically) {
  Mesh m = parseObj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n", "uv.obj");
  std::ostringstream out;
  writeObj(m, out, "test");
  Mesh back = parseObj(out.str(), "back.obj");
  EXPECT_EQ(back.positions, m.positions);
  EXPECT_EQ(back.normals, m.normals);
  EXPECT_EQ(back.uvs, m.uvs);
  EXPECT_EQ(back.triangles, m.triangles);
}

TEST(Obj, RealScalpMeshesRead) {
  std::filesystem::path real = test::realData();
  if (!std::filesystem::exists(real)) GTEST_SKIP() << "shared/testdata/real is absent";
  MeshReadStats stats;
  Mesh scalp = readObj(real / "karthik_hairsim" / "scalp.obj", &stats);  // quads, normals indexed apart
  EXPECT_GT(scalp.triangleCount(), 0u);
  EXPECT_TRUE(stats.normalsFromFile);
  Mesh bare = readObj(real / "neuralhaircut" / "final_scalp.obj", &stats);  // no normals
  EXPECT_FALSE(stats.normalsFromFile);
  for (const glm::vec3& n : bare.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f);
}

}  // namespace
}  // namespace hairgen
