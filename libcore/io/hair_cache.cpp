#include "libcore/io/hair_cache.h"

#include "libcore/io/gltf_io.h"
#include "libcore/io/hair_io.h"
#include "libcore/util/error.h"
#include "libcore/util/text.h"

namespace hairgen {

HairFormat hairFormatOf(const std::filesystem::path& file) {
  std::string ext = toLower(file.extension().string());
  if (ext == ".hair") return HairFormat::kHair;
  if (ext == ".gltf") return HairFormat::kGltf;
  if (ext == ".glb") return HairFormat::kGlb;
  throw InputError({file.string(), 0}, "unknown hair file extension '" + file.extension().string() +
                                           "'; use .hair, .gltf or .glb");
}

Strands readStrands(const std::filesystem::path& file) {
  return hairFormatOf(file) == HairFormat::kHair ? readHair(file) : readGltf(file);
}

void writeStrands(const std::filesystem::path& file, const Strands& strands) {
  const HairFormat format = hairFormatOf(file);
  if (format == HairFormat::kHair)
    writeHair(file, strands);
  else
    writeGltf(file, strands, format == HairFormat::kGlb);
}

}  // namespace hairgen
