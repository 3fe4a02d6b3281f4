// JSON text for people and farm scripts. Strings from files (provenance, paths) may hold bytes that are
// not UTF-8; nlohmann::json would throw on them while writing, so they are written as U+FFFD instead.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace hairgen {

inline std::string jsonText(const nlohmann::ordered_json& value, int indent = 2) {
  return value.dump(indent, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace hairgen
