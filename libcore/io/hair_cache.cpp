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
};
constexpr FormatEntry kFormats[] = {
    {".hair", HairFormat::kHair, "cyHair .hair"},        {".gltf", HairFormat::kGltf, "glTF"},
    {".glb", HairFormat::kGlb, "binary glTF"},           {".ply", HairFormat::kPly, "PLY"},
    {".data", HairFormat::kData, "USC-HairSalon .data"}, {".usda", HairFormat::kUsda, "USD (usda)"},
};

}  // namespace

std::string hairExtensionList() {
  std::string known;
  for (const FormatEntry& f : kFormats) known += std::string(known.empty() ? "" : ", ") + f.extension;
  return known;
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

Strands readStrands(const std::filesystem::path& file, const UnitConversion& conversion) {
  Strands strands;
  const HairFormat format = hairFormatOf(file);
  switch (format) {
    case HairFormat::kHair:
      strands = readHair(file);
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
    case HairFormat::kUsda:
      throw InputError({file.string(), 0},
                       "hairgen writes USD but does not read it; convert the strands to .hair, .ply or .glb "
                       "where they were made");
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
