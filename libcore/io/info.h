// What a file holds, in a few lines or as JSON: `hairgen info`.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

namespace hairgen {

// Describes a .hair, .gltf, .glb or .obj file as JSON (counts, bounds, arrays present, provenance).
// Throws InputError for unreadable or unknown files.
nlohmann::ordered_json describeFile(const std::filesystem::path& file);

// The same description as a few human-readable lines.
std::string formatDescription(const nlohmann::ordered_json& description);

}  // namespace hairgen
