#include "libcore/io/hair_cache.h"

#include "libcore/io/gltf_io.h"
#include "libcore/io/hair_io.h"
#include "libcore/io/hairsalon_io.h"
#include "libcore/io/ply_io.h"
#include "libcore/io/usd_io.h"
#include "libcore/util/error.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

struct FormatEntry {
  const char* extension;
  HairFormat format;
  const char* description;
  bool read;  // readStrands reads it; hairgen writes every format
};
constexpr FormatEntry kFormats[] = {
    {".hair", HairFormat::kHair, "cyHair .hair", true},
    {".gltf", HairFormat::kGltf, "glTF", true},
    {".glb", HairFormat::kGlb, "binary glTF", true},
    {".ply", HairFormat::kPly, "PLY", true},
    {".data", HairFormat::kData, "USC-HairSalon .data", true},
    {".usda", HairFormat::kUsda, "USD (usda)", false},
};

std::string extensionList(bool readOnly) {
  std::string known;
  for (const FormatEntry& f : kFormats)
    if (f.read || !readOnly) known += std::string(known.empty() ? "" : ", ") + f.extension;
  return known;
}

}  // namespace

std::string hairExtensionList() {
  return extensionList(false);
}

std::string readHairExtensionList() {
  return extensionList(true);
}

bool hairgenReads(HairFormat format) {
  for (const FormatEntry& f : kFormats)
    if (f.format == format) return f.read;
  return false;
}

std::optional<HairFormat> hairFormatFor(const std::filesystem::path& file) {
  const std::string ext = toLower(file.extension().string());
  for (const FormatEntry& f : kFormats)
    if (ext == f.extension) return f.format;
  return std::nullopt;
}

HairFormat hairFormatOf(const std::filesystem::path& file) {
  if (const std::optional<HairFormat> format = hairFormatFor(file)) return *format;
  throw InputError({file.string(), 0}, "unknown hair file extension '" + file.extension().string() +
                                           "'; use " + hairExtensionList());
}

const char* describe(HairFormat format) {
  for (const FormatEntry& f : kFormats)
    if (f.format == format) return f.description;
  return "?";
}

void noteSource(Strands& strands, const std::filesystem::path& file) {
  if (strands.provenance.producer.empty() && strands.provenance.source.empty())
    strands.provenance.source = file.filename().string();
}

Strands readStrands(const std::filesystem::path& file, const UnitConversion& conversion,
                    ArrayStorage storage) {
  Strands strands;
  const HairFormat format = hairFormatOf(file);
  if (!hairgenReads(format))
    throw InputError({file.string(), 0}, std::string("hairgen writes ") + describe(format) +
                                             " but does not read it; it reads " + readHairExtensionList());
  switch (format) {
    case HairFormat::kHair:
      strands = readHair(file, nullptr, storage);
      break;
    case HairFormat::kGltf:
    case HairFormat::kGlb:
      strands = readGltf(file);
      break;
    case HairFormat::kPly:
      strands = readPly(file);
      break;
    case HairFormat::kData:
      strands = readHairSalon(file);
      break;
    case HairFormat::kUsda:  // refused above: hairgenReads is false
      break;
  }
  noteSource(strands, file);
  const bool statesDefaults =
      format != HairFormat::kData && (format != HairFormat::kPly || !strands.provenance.producer.empty());
  convertToHairgenFrame(strands, conversion);
  if (!statesDefaults) strands.defaultThickness = Strands{}.defaultThickness;
  return strands;
}

WriteReport writeStrands(const std::filesystem::path& file, const Strands& strands,
                         const WriteOptions& options) {
  const HairFormat format = hairFormatOf(file);
  switch (format) {
    case HairFormat::kHair:
      writeHair(file, strands);
      break;
    case HairFormat::kGltf:
    case HairFormat::kGlb: {
      WriteReport report;
      writeGltf(file, strands, format == HairFormat::kGlb, &report.droppedStrands);
      return report;
    }
    case HairFormat::kPly:
      writePly(file, strands, options.asciiPly);
      break;
    case HairFormat::kData:
      writeHairSalon(file, strands);
      break;
    case HairFormat::kUsda:
      return WriteReport{writeUsda(file, strands).droppedStrands};
  }
  return {};
}

}  // namespace hairgen
