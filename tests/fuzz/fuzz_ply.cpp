// Fuzzes decodePly (libcore/io/ply_io.h): the input is a whole PLY file, ASCII or binary, strands as a
// per-strand count or an edge list. Findings: see fuzz_target.h.
#include <cstddef>
#include <cstdint>

#include "libcore/io/ply_io.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  hairgen::fuzz::readOrReject("decodePly", [&] {
    hairgen::PlyHeader header;
    hairgen::decodePly(data, size, "fuzz.ply", &header);
  });
  return 0;
}
