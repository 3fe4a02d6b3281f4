// JSON text for people and farm scripts. Strings from files (provenance, paths) may hold bytes that are
// not UTF-8; nlohmann::json would throw on them while writing, so they are written as U+FFFD instead.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "libcore/util/text.h"

namespace hairgen {

inline std::string jsonText(const nlohmann::ordered_json& value, int indent = 2) {
  return value.dump(indent, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

// `value` with every string in it, object keys included, passed through printableText (text.h): what a
// file said, made fit to print on a terminal and in JSON.
inline nlohmann::ordered_json printableJson(const nlohmann::ordered_json& value) {
  if (value.is_string()) return printableText(value.get_ref<const std::string&>());
  if (value.is_array()) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const nlohmann::ordered_json& item : value) out.push_back(printableJson(item));
    return out;
  }
  if (value.is_object()) {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (const auto& [key, item] : value.items()) out[printableText(key)] = printableJson(item);
    return out;
  }
  return value;
}

}  // namespace hairgen
