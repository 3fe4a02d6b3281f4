// USC-HairSalon .data strands (Hu et al. 2015, the data set's own layout; DESIGN §6), all little-endian:
//   int32 strand count, then per strand int32 point count and that many float32 x y z.
// Points only: no widths, colours or ids, and no header to say units or up axis (the data set's
// strands are in metres with +y up, but files in this layout come from many tools, so hairgen records
// them as unknown). A strand of one point is how the data set marks a follicle with no hair.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "libcore/model/strands.h"

namespace hairgen {

std::vector<uint8_t> encodeHairSalon(const Strands& strands);

// Every count is checked against the bytes that follow before anything is allocated; a negative,
// truncated or inconsistent file is an InputError naming `name`.
Strands decodeHairSalon(const uint8_t* data, size_t size, const std::string& name);

Strands readHairSalon(const std::filesystem::path& file);
void writeHairSalon(const std::filesystem::path& file, const Strands& strands);  // atomic

}  // namespace hairgen
