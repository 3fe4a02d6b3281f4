// Mutation loop: thousands of deterministic random edits of a valid config, OBJ, .hair and .glb. Every
// one must either parse or raise a typed hairgen error; a crash, a sanitizer report, a hang or any
// other exception fails. Built and run under AddressSanitizer and UndefinedBehaviorSanitizer.
#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "libcore/config/setup.h"
#include "libcore/io/gltf_io.h"
#include "libcore/io/hair_io.h"
#include "libcore/io/hairsalon_io.h"
#include "libcore/io/obj_io.h"
#include "libcore/io/ply_io.h"
#include "libcore/util/error.h"
#include "tests/test_util.h"

namespace hairgen {
namespace {

constexpr int kMutationsPerFormat = 2500;

std::vector<uint8_t> mutate(const std::vector<uint8_t>& original, std::mt19937& rng) {
  std::vector<uint8_t> data = original;
  int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits && !data.empty(); ++e) {
    size_t at = rng() % data.size();
    switch (rng() % 6) {
      case 0:
        data[at] ^= static_cast<uint8_t>(1u << (rng() % 8));
        break;  // flip a bit
      case 1:
        data[at] = static_cast<uint8_t>(rng());
        break;  // random byte
      case 2:
        data.resize(at);
        break;  // truncate
      case 3:
        data.insert(data.begin() + at, static_cast<uint8_t>(rng()));
        break;  // insert
      case 4:
        data.erase(data.begin() + at);
        break;   // delete
      case 5: {  // interesting value
        static const uint8_t values[] = {0x00, 0xff, 0x7f, 0x80, '-', '.', 'e', '9', '#', '"', '\n', '/'};
        data[at] = values[rng() % sizeof values];
        break;
      }
    }
  }
  return data;
}

template <typename Parse>
void mutationLoop(const std::vector<uint8_t>& valid, uint32_t seed, Parse parse) {
  ASSERT_NO_THROW(parse(valid));
  std::mt19937 rng(seed);
  int accepted = 0, rejected = 0;
  for (int i = 0; i < kMutationsPerFormat; ++i) {
    std::vector<uint8_t> input = mutate(valid, rng);
    try {
      parse(input);
      ++accepted;
    } catch (const Error&) {
      ++rejected;
    } catch (const std::exception& e) {
      FAIL() << "mutation " << i << " raised an untyped exception: " << e.what();
    }
  }
  EXPECT_GT(rejected, 0);
  ::testing::Test::RecordProperty("accepted", accepted);
}

std::vector<uint8_t> bytes(const std::string& s) {
  return {s.begin(), s.end()};
}
std::string str(const std::vector<uint8_t>& b) {
  return {b.begin(), b.end()};
}

TEST(Mutation, ConfigFilesOnlyGiveTypedErrors) {
  const std::string hairstyle =
      "# hairstyle\nVisualityStep 0.0025\nCollisionStep 0.0050\nMaxiter 5\nEpsilon 0.0001\n"
      "HairLengths 0.01 0.01 0.01 0.01\nHairDensity 80\nHairRadius1 0.000035\nHairRadius2 0.000050\n"
      "HelixRadius 0.050\nHelixStep 0.050\nPoisson 0.48\nYoung 1000000000\nDensity 13000\nGravity 9.81\n";
  mutationLoop(bytes(hairstyle), 1,
               [](const std::vector<uint8_t>& d) { readHairstyle(test::text(str(d)), {}); });
  const std::string collision =
      "Elipsoid 0.04 10.00 0.00 0.07 0.01 0.08 0.08 0.11 1 0 0 0 1 0 0 0 1\nSphere -0.02 0.01 0.00 0.04 0.16 "
      "0.10\n"
      "Cuboid 0 1 0 0 0 0.1 0.1 0.1 1 0 0 0 1 0 0 0 1\n";
  mutationLoop(bytes(collision), 2,
               [](const std::vector<uint8_t>& d) { readCollision(test::text(str(d)), {}); });
  const std::string setup =
      "Load false\nSave true\nSaveFile \"out dir/x.hair\"\nWickModel wick.obj\nHairstyleInfo h.txt\n";
  mutationLoop(bytes(setup), 3, [](const std::vector<uint8_t>& d) { readSetup(test::text(str(d)), {}); });
  const std::string render =
      "Resolution 64 48\nCameraPosition 0 0 1\nLayerSizes 0.01 0.02 0.03 0.04\nShadingModel thesis\n";
  mutationLoop(bytes(render), 4, [](const std::vector<uint8_t>& d) { readRender(test::text(str(d)), {}); });
}

TEST(Mutation, ObjFilesOnlyGiveTypedErrors) {
  const std::string obj =
      "# quad and triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nvn 0 0 1\nvn 0 1 0\nvt 0 0\nvt "
      "1 1\n"
      "f 1/1/1 2/2/1 3/1/1 4/2/1\nf 1//2 2//2 5//2\nf -1 -2 -3\n";
  mutationLoop(bytes(obj), 5, [](const std::vector<uint8_t>& d) { parseObj(str(d), "m.obj"); });
}

TEST(Mutation, HairFilesOnlyGiveTypedErrors) {
  std::vector<uint8_t> hair = encodeHair(test::sampleStrands(5));
  mutationLoop(hair, 6, [](const std::vector<uint8_t>& d) { decodeHair(d.data(), d.size(), "m.hair"); });
}

TEST(Mutation, GlbFilesOnlyGiveTypedErrors) {
  std::vector<uint8_t> glb = encodeGltf(test::sampleStrands(4), true);
  mutationLoop(glb, 7, [](const std::vector<uint8_t>& d) { decodeGltf(d.data(), d.size(), "m.glb"); });
}

TEST(Mutation, PlyFilesOnlyGiveTypedErrors) {
  mutationLoop(encodePly(test::sampleStrands(4), false), 8,
               [](const std::vector<uint8_t>& d) { decodePly(d.data(), d.size(), "m.ply"); });
  mutationLoop(encodePly(test::sampleStrands(3), true), 9,
               [](const std::vector<uint8_t>& d) { decodePly(d.data(), d.size(), "m.ply"); });
}

TEST(Mutation, HairSalonFilesOnlyGiveTypedErrors) {
  mutationLoop(encodeHairSalon(test::sampleStrands(5)), 10,
               [](const std::vector<uint8_t>& d) { decodeHairSalon(d.data(), d.size(), "m.data"); });
}

}  // namespace
}  // namespace hairgen
