// Writes .glb and .gltf files covering every attribute hairgen stores, for the Khronos validator test.
#include <iostream>

#include "libcore/io/gltf_io.h"
#include "tests/test_util.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: write_samples DIR\n";
    return 2;
  }
  std::filesystem::path dir = argv[1];
  hairgen::Strands full = hairgen::test::sampleStrands(25, 3);
  hairgen::writeGltf(dir / "full.glb", full, true);
  hairgen::writeGltf(dir / "full.gltf", full, false);
  hairgen::Strands bare;
  bare.addStrand({glm::vec3(0, 0, 0), glm::vec3(0, -0.01f, 0.001f), glm::vec3(0, -0.02f, 0.003f)});
  hairgen::writeGltf(dir / "bare.glb", bare, true);
  return 0;
}
