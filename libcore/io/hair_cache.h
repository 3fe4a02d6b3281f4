// Reading and writing strands by file extension (DESIGN §6), the one place extensions are read:
//   .hair        cyHair + hairgen's chunks (hair_io)        read, write
//   .gltf .glb   glTF 2.0 LINES (gltf_io)                   read, write
//   .ply         PLY strands, ASCII or binary (ply_io)     read, write
//   .data        USC-HairSalon (hairsalon_io)               read, write
//   .usda        USD BasisCurves (usd_io)                   write only
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "libcore/io/hair_io.h"
#include "libcore/model/strands.h"
#include "libcore/model/units.h"

namespace hairgen {

enum class HairFormat { kHair, kGltf, kGlb, kPly, kData, kUsda };

// The format a path's extension names (case-insensitive). Throws InputError for any other extension.
HairFormat hairFormatOf(const std::filesystem::path& file);
// The same, or nullopt for an extension that names no hair format.
std::optional<HairFormat> hairFormatFor(const std::filesystem::path& file);
// The extensions hairFormatOf knows, in its order: ".hair, .gltf, .glb, .ply, .data, .usda"; writeStrands
// writes them all.
std::string hairExtensionList();
// Those readStrands reads, in the same order: ".hair, .gltf, .glb, .ply, .data" (USD is export only).
std::string readHairExtensionList();
// Whether readStrands reads `format`.
bool hairgenReads(HairFormat format);

// "cyHair .hair", "PLY", ... for messages and `hairgen info`.
const char* describe(HairFormat format);

// Reads any format hairgen reads (hairgenReads; InputError naming them for another), then applies
// `conversion` (convertToHairgenFrame). A file hairgen did not write (no hairgen provenance) gets its name
// as Provenance::source, so what is made from it can say where it came from. PLY and .data files state
// no default width: theirs is hairgen's default, in metres after the conversion (a cyHair header's own
// default is scaled with the file). `storage`: how a .hair file's point arrays are held (hair_io.h).
Strands readStrands(const std::filesystem::path& file, const UnitConversion& conversion = {},
                    ArrayStorage storage = ArrayStorage::kCopied);

// How formats with a choice are written.
struct WriteOptions {
  bool asciiPly = false;  // PLY as ASCII text instead of binary little-endian
};
// What a format left out of the strands it was given, for the command to say.
struct WriteReport {
  // One-point strands (bare follicles): USD's linear curves need two points (usd_io.h), and in glTF
  // such a strand would be a loose vertex readers join to the strand before it (gltf_io.h).
  size_t droppedStrands = 0;
};
WriteReport writeStrands(const std::filesystem::path& file, const Strands& strands,
                         const WriteOptions& options = {});  // atomic

// Records `file`'s name as the strands' source when they carry no hairgen provenance.
void noteSource(Strands& strands, const std::filesystem::path& file);

}  // namespace hairgen
