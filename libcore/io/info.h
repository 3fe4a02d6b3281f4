// What a file holds, in a few lines or as JSON: `hairgen info`.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "libcore/config/params.h"
#include "libcore/model/mesh.h"

namespace hairgen {

// Describes a .hair, .gltf, .glb or .obj file as JSON (counts, bounds, arrays present, provenance).
// Every string in it is printableText (text.h). Throws InputError for unreadable or unknown files.
nlohmann::ordered_json describeFile(const std::filesystem::path& file);

// The same description as a few human-readable lines.
std::string formatDescription(const nlohmann::ordered_json& description);

// What `hairgen check` reports of a job: the digest, the counts that shape the work, and each mesh the
// Setup names (read, so a broken mesh is found before the work).
// `wick` and `head`: the meshes as the Setup reads them (units, axis, group); read from the files as
// they are when null.
nlohmann::ordered_json describeSetup(const std::string& setupName, const Config& config,
                                     const Mesh* wick = nullptr, const Mesh* head = nullptr);
std::string formatSetupReport(const nlohmann::ordered_json& report);

}  // namespace hairgen
