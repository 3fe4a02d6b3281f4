// Fuzzes decodeGltf (libcore/io/gltf_io.h): the input is a .glb (when it starts with "glTF") or the
// JSON of a .gltf, decoded from memory with an empty base folder. With no folder every external URI
// must be refused and never read; only data: URIs and the .glb's own BIN chunk may supply bytes.
// Findings: see fuzz_target.h; also a decode that succeeds although the file names a buffer or image
// by an external URI (the reader must have read, or pretended to read, a file it may not open).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

#include "libcore/io/gltf_io.h"
#include "tests/fuzz/fuzz_target.h"

namespace {

// The JSON text of the input: the whole of a .gltf, the first chunk of a .glb ("" when there is none).
std::string jsonText(const uint8_t* data, size_t size) {
  if (size < 4 || std::memcmp(data, "glTF", 4) != 0)
    return std::string(reinterpret_cast<const char*>(data), size);
  if (size < 20) return {};
  uint32_t length;
  std::memcpy(&length, data + 12, 4);
  return length <= size - 20 ? std::string(reinterpret_cast<const char*>(data) + 20, length) : std::string();
}

// Whether a buffer or an image of the JSON names anything but a data: URI.
bool namesExternalUri(const std::string& json) {
  const nlohmann::json doc = nlohmann::json::parse(json, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return false;
  for (const char* list : {"buffers", "images"}) {
    if (!doc.contains(list) || !doc[list].is_array()) continue;
    for (const nlohmann::json& entry : doc[list])
      if (entry.is_object() && entry.contains("uri") && entry["uri"].is_string() &&
          entry["uri"].get<std::string>().rfind("data:", 0) != 0)
        return true;
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  hairgen::fuzz::readOrReject("decodeGltf", [&] {
    hairgen::decodeGltf(data, size, "fuzz.gltf", /*baseDir=*/{});
    if (namesExternalUri(jsonText(data, size)))
      hairgen::fuzz::finding("decodeGltf accepted a file naming an external URI with no base folder");
  });
  return 0;
}
