// Fuzzes the restart-state checks (libcore/io/restart_state.h) behind the .hair reader: the input is a
// whole .hair file, a simulated frame with its DYNS chunk, decoded by decodeHair and then checked as the
// restart of a simulation of guides with its own strand layout and points, for each model, with the
// provenance it claims (so the fuzzer reaches the state's values, not only the digests). Findings: see
// fuzz_target.h; a state the checks accept must also hold only finite values.
//
// A custom mutator makes every chunk's CRC-32 right again after libFuzzer's mutation, so mutated states
// and provenance reach the checks instead of stopping at the reader's CRC test (fuzz_hair covers that).
#include <zlib.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "libcore/io/hair_io.h"
#include "libcore/io/restart_state.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t maxSize);

// libFuzzer's mutation, then the CRC of each chunk of the block that starts at the last "HGEN" (the
// chunk block's magic), as far as the chunks' lengths stay inside the input.
extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t maxSize, unsigned int) {
  size = LLVMFuzzerMutate(data, size, maxSize);
  size_t at = size;
  for (size_t i = 0; i + 12 <= size; ++i)
    if (std::memcmp(data + i, "HGEN", 4) == 0) at = i;
  if (at == size) return size;
  uint32_t chunks = 0;
  std::memcpy(&chunks, data + at + 8, 4);
  size_t next = at + 12;
  for (uint32_t c = 0; c < chunks && next + 12 <= size; ++c) {
    uint64_t length = 0;
    std::memcpy(&length, data + next + 4, 8);
    if (length > size - next - 12 || size - next - 12 - length < 4) break;
    const uint32_t crc = uint32_t(crc32(0L, data + next, uInt(12 + length)));
    std::memcpy(data + next + 12 + length, &crc, 4);
    next += 12 + length + 4;
  }
  return size;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  hairgen::fuzz::readOrReject("decodeHair + checkRestartState", [&] {
    hairgen::HairHeader header;
    const hairgen::Strands cache = hairgen::decodeHair(data, size, "fuzz.hair", &header);
    hairgen::Strands rest = cache;
    rest.simulationState.clear();
    rest.provenance = {};
    const hairgen::Provenance& p = cache.provenance;
    for (hairgen::DynamicsModel model : hairgen::kDynamicsModels) {
      hairgen::fuzz::readOrReject("checkRestartState", [&] {
        hairgen::checkRestartState(
            rest, cache,
            hairgen::RestartExpectation{model, p.frame.value_or(0), p.configDigest, p.restDigest},
            "fuzz.hair");
        if (model == hairgen::DynamicsModel::kSprings)
          for (double value : cache.simulationState)
            if (!std::isfinite(value))
              hairgen::fuzz::finding("a springs state with a non-finite value passed");
      });
    }
    hairgen::fuzz::readOrReject("restGuidesDigest", [&] { hairgen::restGuidesDigest(rest); });
  });
  return 0;
}
