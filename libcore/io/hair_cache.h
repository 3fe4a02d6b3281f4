// Reading and writing strands by file extension: .hair, .gltf or .glb.
#pragma once

#include <filesystem>

#include "libcore/model/strands.h"

namespace hairgen {

enum class HairFormat { kHair, kGltf, kGlb };

// The format a path's extension names (case-insensitive). Throws InputError for any other extension.
HairFormat hairFormatOf(const std::filesystem::path& file);

Strands readStrands(const std::filesystem::path& file);
void writeStrands(const std::filesystem::path& file, const Strands& strands);  // atomic

}  // namespace hairgen
