// Fuzzes parseObj (libcore/io/obj_io.h): the input is the text of a Wavefront OBJ mesh, read as a
// wick or a head is. Findings: see fuzz_target.h.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "libcore/io/obj_io.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  hairgen::fuzz::readOrReject("parseObj", [&] {
    hairgen::MeshReadStats stats;
    hairgen::parseObj(text, "fuzz.obj", &stats);
  });
  return 0;
}
