// glTF 2.0 caches (.gltf with an embedded buffer, or .glb), written and read with tinygltf (DESIGN §6).
//
// One mesh, one primitive in mode LINES with uint32 indices: each strand is a run of consecutive
// vertices joined by segments (i, i+1), so strand boundaries follow from the indices. Attributes per
// vertex: POSITION (with min/max); COLOR_0 (RGB in [0, 1]; _COLOR holds the unclamped values when a
// colour passes 1, as a per-strand ambient coefficient may); NORMAL where shaded; custom _TANGENT, _THICKNESS
// (diameter, metres), _TRANSPARENCY; and, repeated on every vertex of a strand, _STRAND_ID, _ROOT_UV,
// _GUIDE_IDS, _GUIDE_WEIGHTS, _ROOT_TRIANGLE, _ROOT_BARY. glTF forbids UNSIGNED_INT vertex attributes,
// so the ids are FLOAT, exact below 2^24 (writing a larger id is an error: use .hair). asset.extras
// names the producer, the counts, the provenance and the cyHair defaults.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "libcore/model/strands.h"

namespace hairgen {

std::vector<uint8_t> encodeGltf(const Strands& strands, bool binary);

// Decodes .glb (detected by its magic) or .gltf JSON. `baseDir` resolves external buffers of .gltf
// files. Every accessor is checked against its buffer before it is read.
Strands decodeGltf(const uint8_t* data, size_t size, const std::string& name,
                   const std::filesystem::path& baseDir = {});

Strands readGltf(const std::filesystem::path& file);
// Writes atomically: binary .glb when `binary`, else .gltf JSON with the buffer embedded. The caller
// decides from the file's format (hairFormatOf), the one place extensions are read.
void writeGltf(const std::filesystem::path& file, const Strands& strands, bool binary);

}  // namespace hairgen
