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
  // Converted from a file of unknown units: no thickness, no colours, the extras say what is unknown.
  bare.provenance = {"hairgen test", "convert", 0, ""};
  bare.provenance.source = "Bangs_100.data";
  bare.provenance.metres = bare.provenance.yUp = false;
  hairgen::writeGltf(dir / "converted.glb", bare, true);
  return 0;
}
