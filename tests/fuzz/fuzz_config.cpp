// Fuzzes the config reader (libcore/config/reader.h, keys.h): the input is the text of a config file.
// Its first line is tried as a --set argument (parseOverride); when it parses, the rest of the input is
// the config text and the readers apply the override, as `--set Section.Key=VALUE` does, else the whole
// input is. parseConfigText splits the text into lines of tokens; then every section reader (Setup,
// Hairstyle, Collision, Visuality, Render Info) reads it, as a Setup or a section file would be read.
// Findings: see fuzz_target.h.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "libcore/config/keys.h"
#include "libcore/config/reader.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hairgen;
  std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<Override> overrides;
  const size_t firstLineEnd = text.find('\n');
  fuzz::readOrReject("parseOverride",
                     [&] { overrides.push_back(parseOverride(text.substr(0, firstLineEnd))); });
  if (!overrides.empty())
    text = firstLineEnd == text.npos ? std::string_view() : text.substr(firstLineEnd + 1);

  std::optional<ConfigText> config;
  fuzz::readOrReject("parseConfigText", [&] { config = parseConfigText(text, "fuzz.txt", "fuzz-dir"); });
  if (!config) return 0;
  fuzz::readOrReject("readSetup", [&] { readSetup(*config, overrides); });
  fuzz::readOrReject("readHairstyle", [&] { readHairstyle(*config, overrides); });
  fuzz::readOrReject("readCollision", [&] { readCollision(*config, overrides); });
  fuzz::readOrReject("readVisuality", [&] { readVisuality(*config, overrides); });
  fuzz::readOrReject("readRender", [&] { readRender(*config, overrides); });
  return 0;
}
