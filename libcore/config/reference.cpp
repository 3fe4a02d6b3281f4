// The key reference, made from the declarations so that it cannot drift from what the reader accepts.
#include <string>

#include "libcore/config/reader.h"

namespace hairgen {
namespace {

// Markdown table cells must not hold a bare '|'.
std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

}  // namespace

std::string keyReference(const SectionList& sections) {
  std::string out =
      "# Config keys\n\n"
      "Every key hairgen reads, generated from its declaration (`libcore/config/keys_SECTION.cpp`) by "
      "`hairgen check "
      "--keys`;\n`scripts/config-keys.sh` rewrites this file, and the build fails when it is stale. Keys are "
      "case-insensitive,\n`#` starts a comment, paths are relative to the file that names them, and any "
      "value "
      "can be overridden\nwith `--set Section.Key=VALUE`. A default is what the canonical text behind the "
      "config "
      "digest writes\nfor a file that leaves the key out.\n";
  for (const SectionSpec* section : sections) {
    out += "\n## " + section->title + "\n\n";
    if (section->file.empty())
      out += "The file named on the command line; `--set " + section->name + ".KEY=VALUE`.\n\n";
    else
      out +=
          "The file the Setup's `" + section->file + "` names; `--set " + section->name + ".KEY=VALUE`.\n\n";
    out += "| key | value | unit | default | meaning |\n|---|---|---|---|---|\n";
    for (const KeySpec& key : section->keys) {
      std::string value = key.value;
      if (!key.range.empty())
        value += (key.range[0] == '>' || key.range[0] == '<' ? " " : " in ") + key.range;
      std::string defaultText = key.required              ? "required"
                                : key.defaultText.empty() ? "none"
                                                          : key.defaultText;
      std::string notes;
      if (key.repeatable) notes += " Repeatable.";
      if (!notes.empty() || !key.aliases.empty() || !key.inDigest) notes = "." + notes;
      if (!key.aliases.empty()) {
        notes += " Also spelled";
        for (size_t i = 0; i < key.aliases.size(); ++i) notes += (i ? ", `" : " `") + key.aliases[i] + "`";
        notes += ".";
      }
      if (!key.inDigest) notes += " Not in the config digest.";
      out += "| `" + key.name + "` | " + cell(value) + " | " + cell(key.unit) + " | " + cell(defaultText) +
             " | " + cell(key.help + notes) + " |\n";
    }
  }
  return out;
}

}  // namespace hairgen
