// PLY strands (DESIGN §6), as the hair data sets write them (CT2Hair through hairutil, whose files are
// the example): a `vertex` element with x y z, and the strands either as a `strand` element with a
// count per strand (`nsegs`, segments, as hairutil writes; or `vertex_count`, points) or, when there
// is none, as an `edge` element (vertex1 vertex2) joining consecutive vertices. ASCII, binary
// little-endian and binary big-endian are read; ASCII and binary little-endian are written.
//
// Read besides the points, when present: vertex nx ny nz (normals), tangent_x tangent_y tangent_z,
// red green blue (uchar or ushort scaled to [0, 1], float or double as they are), thickness (a
// diameter, hairutil's name), transparency; per strand strand_id, root_triangle, root_bary0-2, root_u
// root_v, guide0-2, weight0-2 (hairgen's names, after the .hair chunks). Other elements (a head's
// faces) and properties are skipped; a file with faces and neither strands nor edges is refused.
//
// Written: the vertex element with every per-point array the strands carry (colours as uchar, the
// data sets' convention and what hairutil reads: 8 bits), the strand element with nsegs (ushort, or
// uint when a strand has more than 65536 points) and the per-strand arrays, and an edge element
// (int vertex1 vertex2) so MeshLab and Blender show the strands as lines. hairgen's provenance and the
// cyHair defaults go in `comment hairgen key=value` lines; other comments are the source's own
// description (Provenance::sourceInfo). Units and up axis are the file's own, unknown unless hairgen
// wrote the file in metres.
//
// Every count in the header is checked against the bytes that follow before anything is allocated.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "libcore/model/strands.h"

namespace hairgen {

// What the header says, for `hairgen info`.
struct PlyHeader {
  std::string format;                 // "ascii", "binary_little_endian" or "binary_big_endian"
  std::vector<std::string> elements;  // "vertex 1165: x y z red green blue", in file order
  std::string strandsFrom;            // "strand nsegs", "strand vertex_count" or "edge"
};

std::vector<uint8_t> encodePly(const Strands& strands, bool ascii);

// Decodes a PLY image. A malformed or inconsistent file is an InputError naming `name`.
Strands decodePly(const uint8_t* data, size_t size, const std::string& name, PlyHeader* header = nullptr);

Strands readPly(const std::filesystem::path& file, PlyHeader* header = nullptr);
void writePly(const std::filesystem::path& file, const Strands& strands, bool ascii);  // atomic

}  // namespace hairgen
