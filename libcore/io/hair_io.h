// The .hair cache: Cem Yuksel's cyHair layout, then hairgen's own chunk block (DESIGN §6).
//
// Layout, all little-endian:
//   128-byte header   "HAIR", uint32 strands, uint32 points, uint32 array flags
//                     (1 segments, 2 points, 4 thickness, 8 transparency, 16 colour),
//                     uint32 default segments, float default thickness, float default transparency,
//                     float[3] default colour, char[88] info text
//   cyHair arrays     uint16 segments[strands] (points − 1 per strand), float[3] points,
//                     float thickness, float transparency, float[3] colour; each only if its flag is set
//   chunk block       "HGEN", uint32 block version (1), uint32 chunk count, then per chunk:
//                     char tag[4], uint64 payload bytes, payload, uint32 CRC-32 of tag+length+payload
// Chunks: TANG/NORM float[3] per point; SIDS/RTRI uint32 per strand; RBAR float[3] per strand;
// RUVS float[2] per strand; GIDS uint32[3] per strand; GWTS float[3] per strand; DYNS float64s (a
// simulated frame's restart state, each model's layout in restart_state.h); PROV "key=value\n" text
// (provenanceText below: producer, stage, seed, config, frame and time for a frame of a sequence, and what a
// conversion did). cyHair readers stop after the arrays and never see the block. Unknown chunks are skipped
// (after their CRC is checked), so newer files stay readable.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "libcore/model/strands.h"

namespace hairgen {

// The header fields that `Strands` does not carry, for `hairgen info`.
struct HairHeader {
  uint32_t flags = 0;
  uint32_t defaultSegments = 0;
  std::string info;                 // the 88-byte info text, up to its first NUL
  std::vector<std::string> chunks;  // tags of the chunk block, in file order
};

std::vector<uint8_t> encodeHair(const Strands& strands);

// Decodes a .hair image. Every count is checked against `size` before anything is allocated; a
// truncated, corrupt or inconsistent file is an InputError naming `name`.
Strands decodeHair(const uint8_t* data, size_t size, const std::string& name, HairHeader* header = nullptr);

// How a read holds a file's point arrays (points, tangents: 64 KiB or more each): copied into
// memory of their own, or where the file's pages lie (mapped_file.h), neither copied nor, until read,
// the process's. Mapped is for a reader that is done with the file in one command (the render): one
// that rewrites the file in place meanwhile changes what it reads (hairgen's own writes never do).
enum class ArrayStorage { kCopied, kMapped };

// A file without the chunk block was made elsewhere: its provenance says its units and up axis are
// unknown, and its info text is the source's description.
Strands readHair(const std::filesystem::path& file, HairHeader* header = nullptr,
                 ArrayStorage storage = ArrayStorage::kCopied);
void writeHair(const std::filesystem::path& file, const Strands& strands);  // atomic

// Only the provenance of a .hair file, skipping its arrays (what a farm checks before redoing a task);
// an empty provenance for a file without the chunk block. Throws InputError for a file too short for
// what its header declares, and IoError when it cannot be read.
Provenance readHairProvenance(const std::filesystem::path& file);

// Provenance as the PROV chunk's "key=value\n" lines (PLY comments carry the same lines), and back.
// Keys: producer, stage, seed, config; for a file made elsewhere also source, sourceInfo, conversion,
// units=unknown, up=unknown (written only when set); for a shard of a split stage shard=K/N and
// range=FIRST-END/TOTAL. Unknown keys are ignored.
std::string provenanceText(const Provenance& provenance);
Provenance parseProvenance(const std::string& text, const std::string& name);

}  // namespace hairgen
