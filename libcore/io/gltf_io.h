// glTF 2.0 caches (.gltf with an embedded buffer, or .glb), written and read with tinygltf (DESIGN §6).
//
// One mesh, one primitive in mode LINES with uint32 indices: each strand is a run of consecutive
// vertices joined by segments (i, i+1), so strand boundaries follow from the indices. Attributes per
// vertex: POSITION (with min/max); COLOR_0 (RGB in [0, 1]; _COLOR holds the unclamped values when a
// colour passes 1, as a per-strand ambient coefficient may); NORMAL where shaded; custom _TANGENT, _THICKNESS
// (diameter, metres), _TRANSPARENCY; and _STRAND, the vertex's strand (0, 1, ... as FLOAT: glTF forbids
// UNSIGNED_INT vertex attributes, so a file holds fewer than 2^24 strands). Per-strand values are stored
// once per strand, in accessors of one entry per strand that the primitive's extras name
// (extras.perStrand: _STRAND_ID, _ROOT_UV, _GUIDE_IDS, _GUIDE_WEIGHTS, _ROOT_TRIANGLE, _ROOT_BARY; ids
// UNSIGNED_INT, the rest FLOAT): entry _STRAND of each is the vertex's. Files of earlier hairgen, which
// repeated them on every vertex as FLOAT attributes, are still read. One-point strands (bare follicles)
// are not written: a vertex no segment joins is one generic readers attach to the strand before it.
// asset.extras names the producer, the counts, the provenance and the cyHair defaults.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "libcore/model/strands.h"

namespace hairgen {

// Writes the file to `out` in one pass from `strands` (no array copied whole, unless one-point strands are
// to be left out: then withoutOnePointStrands copies the rest first). `droppedStrands`, when given, gets
// the number of one-point strands left out. InputError: nothing to write (no strand of two
// points), 2^24 strands or more, or a .glb past 4 GiB.
void encodeGltf(std::ostream& out, const Strands& strands, bool binary, size_t* droppedStrands = nullptr);
std::vector<uint8_t> encodeGltf(const Strands& strands, bool binary, size_t* droppedStrands = nullptr);

// Decodes .glb (detected by its magic) or .gltf JSON. `baseDir` resolves external buffers of .gltf
// files. Every accessor is checked against its buffer before it is read.
Strands decodeGltf(const uint8_t* data, size_t size, const std::string& name,
                   const std::filesystem::path& baseDir = {});

Strands readGltf(const std::filesystem::path& file);
// Writes atomically: binary .glb when `binary`, else .gltf JSON with the buffer embedded. The caller
// decides from the file's format (hairFormatOf), the one place extensions are read.
void writeGltf(const std::filesystem::path& file, const Strands& strands, bool binary,
               size_t* droppedStrands = nullptr);

}  // namespace hairgen
