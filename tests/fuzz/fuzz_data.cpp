// Fuzzes decodeHairSalon (libcore/io/hairsalon_io.h): the input is a whole USC-HairSalon .data file, an
// int32 strand count then per strand an int32 point count and float32 xyz. Findings: see fuzz_target.h.
#include <cstddef>
#include <cstdint>

#include "libcore/io/hairsalon_io.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  hairgen::fuzz::readOrReject("decodeHairSalon", [&] { hairgen::decodeHairSalon(data, size, "fuzz.data"); });
  return 0;
}
