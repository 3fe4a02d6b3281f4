// Fuzzes readImage (libcore/io/exr_io.h): the input is an OpenEXR file. OpenEXR reads by file name,
// so each input is written to input.exr in a private folder made once per process (under $TMPDIR,
// removed at exit) and read from there, as `hairgen diff` reads its images. OpenEXR (the header
// checked by OpenEXRCore, the pixels read by its C++ reader) is Debian's build, not instrumented: its
// bugs show only as crashes or memory, and coverage guides the fuzzer through hairgen's code alone. Findings:
// see fuzz_target.h.
//
// readImage refuses a declared image larger than memoryBudget(), the machine's free memory. Under
// libFuzzer the process must stay within -rss_limit_mb on any machine, so this target links
// memoryBudget() to fuzzBudget() below instead (-Wl,--wrap in tests/fuzz/CMakeLists.txt): a quarter of
// the RSS limit, leaving the rest to ASan's shadow and quarantine and to OpenEXR's own buffers.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "libcore/io/exr_io.h"
#include "tests/fuzz/fuzz_target.h"

namespace {

std::filesystem::path folder;
uint64_t budget = 0;

void removeFolder() {
  std::error_code ec;
  std::filesystem::remove_all(folder, ec);
}

// libFuzzer's -rss_limit_mb, in bytes (2048 MB unless given; 0, no limit, leaves 2048 MB too).
uint64_t rssLimit(int argc, char** argv) {
  uint64_t megabytes = 0;
  constexpr std::string_view kFlag = "-rss_limit_mb=";
  for (int i = 1; i < argc; ++i)
    if (std::string_view(argv[i]).substr(0, kFlag.size()) == kFlag)
      megabytes = std::strtoull(argv[i] + kFlag.size(), nullptr, 10);
  return (megabytes ? megabytes : 2048) << 20;
}

}  // namespace

// hairgen::memoryBudget() in this target (the linker's --wrap names it by its mangled name).
extern "C" uint64_t __wrap__ZN7hairgen12memoryBudgetEv() {
  return budget;
}

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  budget = rssLimit(*argc, *argv) / 4;
  std::string pattern = (std::filesystem::temp_directory_path() / "hairgen-fuzz-exr-XXXXXX").string();
  if (!mkdtemp(pattern.data())) hairgen::fuzz::finding("cannot make a temporary folder for fuzz_exr");
  folder = pattern;
  std::atexit(removeFolder);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = folder / "input.exr";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) hairgen::fuzz::finding("cannot write the input to the temporary folder");
  }
  hairgen::fuzz::readOrReject("readImage", [&] { hairgen::readImage(file); });
  return 0;
}
