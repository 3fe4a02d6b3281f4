// Fuzzes decodeHair (libcore/io/hair_io.h): the input is a whole .hair file, cyHair header and arrays
// then hairgen's chunk block. Findings: see fuzz_target.h.
#include <cstddef>
#include <cstdint>

#include "libcore/io/hair_io.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  hairgen::fuzz::readOrReject("decodeHair", [&] {
    hairgen::HairHeader header;
    hairgen::decodeHair(data, size, "fuzz.hair", &header);
  });
  return 0;
}
