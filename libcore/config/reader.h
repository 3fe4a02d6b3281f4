// The strict reader of thesis-style text configs (thesis §4.2.1, DESIGN §4).
//
// A config file is one `Key value...` per line; `#` starts a comment; keys are case-insensitive;
// values may be double-quoted to hold spaces. SectionReader hands out typed values and remembers which
// lines it read, so that finish() can reject every line nobody asked for (an unknown key, a key of
// another section) with its file:line and the closest known key.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/params.h"
#include "libcore/util/error.h"

namespace hairgen {

struct ConfigLine {
  FileLoc where;
  std::string key;                  // as written
  std::vector<std::string> values;  // tokens after the key, quotes removed
};

struct ConfigText {
  std::string name;               // display name (the path as given)
  std::filesystem::path baseDir;  // relative paths in values resolve against it
  std::vector<ConfigLine> lines;
};

// Splits text into lines of tokens. Throws InputError on an unterminated quote or a control byte.
ConfigText parseConfigText(std::string_view text, const std::string& name,
                           const std::filesystem::path& baseDir);
ConfigText readConfigText(const std::filesystem::path& file);

// What the reader, --set and the key reference know of one key (schema.h declares the keys).
struct KeySpec {
  std::string name;                  // canonical spelling
  std::vector<std::string> aliases;  // other accepted spellings (the thesis' own)
  std::string value;                 // what the value looks like: "real", "x y z", "superhelix | cantilever"
  std::string unit;                  // SI unit; "" when dimensionless
  std::string range;                 // "(0, 1]", ">= 0"; "" when any value goes
  std::string defaultText;           // the default as the canonical text writes it; "" when none
  std::string help;                  // one line
  bool repeatable = false;           // any number of lines, kept in file order
  bool required = false;
  bool inDigest = true;  // the value shapes the output (paths and flags of the job do not)
  // The values of the section's Model that alone read the key (Dynamics Info: anjyo, springs); empty when
  // every model does. Its help starts with them, and the section's check refuses it under another.
  std::vector<std::string> models;

  // For messages: the value's shape, range and unit, then an example.
  std::string hint() const;
};

struct SectionSpec {
  std::string name;   // "Hairstyle", as used by --set
  std::string title;  // "Hairstyle Info", as used in messages
  std::string file;   // the Setup key that names the section's file ("" for the Setup itself)
  std::vector<KeySpec> keys;

  // The key `written` names (its canonical spelling or an alias, case-insensitively), or null.
  const KeySpec* find(std::string_view written) const;
};

using SectionList = std::vector<const SectionSpec*>;

// Every section hairgen reads, in the order of the canonical text (defined beside the declarations).
const SectionList& allSections();
const SectionSpec& sectionSpec(std::string_view name);

// Parses "Section.Key=VALUE" (VALUE split on whitespace) against `sections`. Throws InputError naming
// the argument, with a hint for an unknown section or key.
Override parseOverride(std::string_view argument, const SectionList& sections = allSections());

// The reference of every key of `sections` as Markdown: what `hairgen check --keys` prints and
// docs/config-keys.md holds.
std::string keyReference(const SectionList& sections = allSections());

// The inclusive range a number must lie in; `open*` excludes that end.
struct Range {
  double min = -1e300, max = 1e300;
  bool openMin = false, openMax = false;
  static Range positive() { return {0.0, 1e300, true, false}; }
  static Range nonNegative() { return {0.0, 1e300, false, false}; }
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  bool contains(double v) const;
  std::string describe() const;
};

class SectionReader {
 public:
  // Applies the overrides aimed at this section: a key's line is replaced (or added), and for a
  // repeatable key all its lines are replaced by the override.
  SectionReader(ConfigText text, const SectionSpec& spec, const std::vector<Override>& overrides);

  bool has(std::string_view key) const;
  FileLoc where(std::string_view key) const;  // the file alone when the key is absent

  // Typed getters. With no fallback the key is required. Each checks count, syntax, finiteness and range.
  double real(std::string_view key, std::optional<double> fallback, Range range = {});
  int64_t integer(std::string_view key, std::optional<int64_t> fallback, int64_t min, int64_t max);
  uint64_t unsignedInteger(std::string_view key, uint64_t fallback);
  std::vector<double> reals(std::string_view key, size_t count, std::optional<std::vector<double>> fallback,
                            Range range = {});
  std::vector<double> realList(std::string_view key, Range range = {});  // one or more, required
  bool boolean(std::string_view key, bool fallback);
  // One of `choices` (compared case-insensitively; returns the canonical spelling from `choices`).
  std::string word(std::string_view key, const std::string& fallback,
                   const std::vector<std::string>& choices);
  PathRef path(std::string_view key);  // empty PathRef when absent

  glm::dvec3 vec3(std::string_view key, glm::dvec3 fallback, Range range = {});

  // The one line of a key (null when absent), marked as read; a duplicate or an empty value is an error.
  const ConfigLine* line(std::string_view key);
  // Every line of a repeatable key, in file order; each value checked by the caller with checkReal().
  std::vector<const ConfigLine*> lines(std::string_view key);
  double checkReal(const ConfigLine& line, size_t index, Range range, std::string_view what) const;

  // Throws for the first line no getter asked for: unknown key, or a key of another section.
  void finish() const;

  const std::string& fileName() const { return text_.name; }
  InputError error(const ConfigLine& line, const std::string& message) const;

 private:
  const KeySpec& spec(std::string_view key) const;
  void expectCount(const ConfigLine& line, size_t count) const;

  ConfigText text_;
  const SectionSpec& section_;
  std::vector<bool> used_;
};

}  // namespace hairgen
