#include "libcore/config/reader.h"

#include <cmath>

#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

std::vector<std::string> spellings(const SectionSpec& section) {
  std::vector<std::string> names;
  for (const KeySpec& k : section.keys) names.push_back(k.name);
  return names;
}

// The canonical name of `written` in `section`, or "" if the section has no such key.
std::string canonicalKey(const SectionSpec& section, std::string_view written) {
  const KeySpec* key = section.find(written);
  return key ? key->name : std::string();
}

// "did you mean ...", or "it belongs in ..." when another section knows the key.
std::string unknownKeyHint(const SectionSpec& section, std::string_view written) {
  for (const SectionSpec* other : allSections())
    if (other->name != section.name && !canonicalKey(*other, written).empty())
      return "; '" + canonicalKey(*other, written) + "' belongs in " + other->title;
  std::string close = closestMatch(written, spellings(section));
  if (!close.empty()) return "; did you mean '" + close + "'?";
  return "; " + section.title + " knows: " + [&] {
    std::string all;
    for (const KeySpec& k : section.keys) all += (all.empty() ? "" : ", ") + k.name;
    return all;
  }();
}

}  // namespace

std::string KeySpec::hint() const {
  std::string text = value;
  if (!range.empty()) text += " " + range;
  if (!unit.empty()) text += " (" + unit + ")";
  if (!defaultText.empty()) text += ", e.g. " + defaultText;
  return text;
}

const KeySpec* SectionSpec::find(std::string_view written) const {
  std::string lower = toLower(written);
  for (const KeySpec& k : keys) {
    if (toLower(k.name) == lower) return &k;
    for (const std::string& alias : k.aliases)
      if (toLower(alias) == lower) return &k;
  }
  return nullptr;
}

const SectionSpec& sectionSpec(std::string_view name) {
  for (const SectionSpec* s : allSections())
    if (toLower(s->name) == toLower(name)) return *s;
  throw InputError("unknown config section '" + std::string(name) + "'");
}

ConfigText parseConfigText(std::string_view text, const std::string& name,
                           const std::filesystem::path& baseDir) {
  ConfigText config{name, baseDir, {}};
  forEachLine(withoutBom(text), [&](std::string_view line, int lineNumber) {
    FileLoc where{name, lineNumber};
    std::vector<std::string> tokens;
    std::string token;
    bool inToken = false, quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      char c = line[i];
      if (quoted) {
        if (c == '"') {
          quoted = false;
        } else {
          token += c;
        }
        continue;
      }
      if (c == '#') break;
      if (c == '"') {
        quoted = inToken = true;
        continue;
      }
      if (c == ' ' || c == '\t' || c == '\f' || c == '\v') {
        if (inToken) tokens.push_back(std::move(token));
        token.clear();
        inToken = false;
        continue;
      }
      if (isControl(c))
        throw InputError(where, "control character (byte " + std::to_string(static_cast<unsigned char>(c)) +
                                    ") in a config file; is this a text file?");
      token += c;
      inToken = true;
    }
    if (quoted) throw InputError(where, "unterminated quoted string; close it with \"");
    if (inToken) tokens.push_back(std::move(token));
    if (!tokens.empty())
      config.lines.push_back(ConfigLine{where, tokens.front(), {tokens.begin() + 1, tokens.end()}});
  });
  return config;
}

ConfigText readConfigText(const std::filesystem::path& file) {
  return parseConfigText(readFileText(file), file.string(), file.parent_path());
}

Override parseOverride(std::string_view argument, const SectionList& sections) {
  FileLoc where{"--set " + std::string(argument), 0};
  for (const char c : argument)
    if (isControl(c))
      throw InputError(where, "holds a control character (byte " +
                                  std::to_string(static_cast<unsigned char>(c)) +
                                  "); a --set value is printable text");
  size_t dot = argument.find('.');
  size_t eq = argument.find('=');
  if (dot == std::string_view::npos || eq == std::string_view::npos || dot > eq)
    throw InputError(where, "expected Section.Key=VALUE, e.g. --set Hairstyle.HairDensity=160");
  std::string sectionName(argument.substr(0, dot));
  const SectionSpec* section = nullptr;
  for (const SectionSpec* s : sections)
    if (toLower(s->name) == toLower(sectionName) || toLower(s->name) + "info" == toLower(sectionName))
      section = s;
  if (!section) {
    std::vector<std::string> names;
    std::string all;
    for (const SectionSpec* s : sections) {
      names.push_back(s->name);
      all += (all.empty() ? "" : ", ") + s->name;
    }
    std::string close = closestMatch(sectionName, names);
    throw InputError(where,
                     "unknown section '" + sectionName + "'" +
                         (close.empty() ? "; sections are " + all : "; did you mean '" + close + "'?"));
  }
  std::string keyName(argument.substr(dot + 1, eq - dot - 1));
  if (!section->find(keyName))
    throw InputError(
        where, "unknown key '" + keyName + "' in " + section->title + unknownKeyHint(*section, keyName));
  ConfigText parsed = parseConfigText(argument.substr(eq + 1), where.file, std::filesystem::current_path());
  std::vector<std::string> values;
  for (const ConfigLine& line : parsed.lines) {
    values.push_back(line.key);
    values.insert(values.end(), line.values.begin(), line.values.end());
  }
  if (values.empty()) throw InputError(where, "no value after '='");
  return Override{section->name, keyName, values, std::string(argument)};
}

bool Range::contains(double v) const {
  if (openMin ? !(v > min) : !(v >= min)) return false;
  if (openMax ? !(v < max) : !(v <= max)) return false;
  return true;
}

std::string Range::describe() const {
  bool hasMin = min > -1e299, hasMax = max < 1e299;
  if (!hasMin && !hasMax) return "";
  if (hasMin && !hasMax) return std::string(openMin ? "> " : ">= ") + formatReal(min);
  if (!hasMin && hasMax) return std::string(openMax ? "< " : "<= ") + formatReal(max);
  return std::string(openMin ? "(" : "[") + formatReal(min) + ", " + formatReal(max) + (openMax ? ")" : "]");
}

SectionReader::SectionReader(ConfigText text, const SectionSpec& spec, const std::vector<Override>& overrides)
    : text_(std::move(text)), section_(spec) {
  for (const Override& o : overrides) {
    if (o.section != section_.name) continue;
    std::string canonical = canonicalKey(section_, o.key);
    ConfigLine line;
    line.where.file = "--set " + o.text;
    line.key = o.key;
    line.values = o.values;
    bool repeatable = this->spec(canonical).repeatable;
    bool replaced = false;
    for (size_t i = 0; i < text_.lines.size();) {
      if (canonicalKey(section_, text_.lines[i].key) != canonical) {
        ++i;
      } else if (repeatable || replaced) {
        text_.lines.erase(text_.lines.begin() + static_cast<std::ptrdiff_t>(i));
      } else {
        text_.lines[i] = line;
        replaced = true;
        ++i;
      }
    }
    if (!replaced) text_.lines.push_back(line);
  }
  used_.assign(text_.lines.size(), false);
}

const KeySpec& SectionReader::spec(std::string_view key) const {
  for (const KeySpec& k : section_.keys)
    if (k.name == key) return k;
  throw std::logic_error("SectionReader: key '" + std::string(key) + "' is not in " + section_.title);
}

InputError SectionReader::error(const ConfigLine& line, const std::string& message) const {
  return InputError(line.where, message);
}

bool SectionReader::has(std::string_view key) const {
  for (const ConfigLine& line : text_.lines)
    if (canonicalKey(section_, line.key) == key) return true;
  return false;
}

FileLoc SectionReader::where(std::string_view key) const {
  for (const ConfigLine& line : text_.lines)
    if (canonicalKey(section_, line.key) == key) return line.where;
  return {text_.name, 0};
}

const ConfigLine* SectionReader::line(std::string_view key) {
  spec(key);
  const ConfigLine* found = nullptr;
  for (size_t i = 0; i < text_.lines.size(); ++i) {
    if (canonicalKey(section_, text_.lines[i].key) != key) continue;
    if (found)
      throw InputError(text_.lines[i].where, "duplicate key '" + std::string(key) + "' (first given at " +
                                                 found->where.str() + "); give it once");
    found = &text_.lines[i];
    used_[i] = true;
  }
  if (found && found->values.empty())
    throw InputError(found->where, "'" + std::string(key) + "' has no value; expected " + spec(key).hint());
  return found;
}

void SectionReader::expectCount(const ConfigLine& line, size_t count) const {
  if (line.values.size() != count)
    throw InputError(line.where, "'" + line.key + "' takes " + std::to_string(count) + " value" +
                                     (count == 1 ? "" : "s") + ", found " +
                                     std::to_string(line.values.size()) + "; expected " +
                                     spec(canonicalKey(section_, line.key)).hint());
}

double SectionReader::checkReal(const ConfigLine& line, size_t index, Range range,
                                std::string_view what) const {
  const std::string& token = line.values.at(index);
  std::optional<double> value = parseReal(token);
  std::string label = what.empty() ? "'" + line.key + "'" : "'" + line.key + "' " + std::string(what);
  if (!value) throw InputError(line.where, label + ": '" + token + "' is not a number");
  if (!std::isfinite(*value)) throw InputError(line.where, label + ": '" + token + "' is not finite");
  if (!range.contains(*value)) {
    const KeySpec* key = section_.find(line.key);
    const std::string unit = key ? key->unit : std::string();
    // Past the ±1e300 every range has, which describe() leaves unsaid ("> 0" reads as no upper bound).
    std::string bound = range.describe() + (unit.empty() ? "" : " " + unit);
    if (std::abs(*value) > 1e299) bound = (range.describe().empty() ? "" : bound + " and ") + "within ±1e300";
    throw InputError(line.where, label + " = " + token + " is out of range; it must be " + bound);
  }
  return *value;
}

double SectionReader::real(std::string_view key, std::optional<double> fallback, Range range) {
  const ConfigLine* line = this->line(key);
  if (!line) {
    if (!fallback)
      throw InputError({text_.name, 0},
                       "missing required key '" + std::string(key) + "' (" + spec(key).hint() + ")");
    return *fallback;
  }
  expectCount(*line, 1);
  return checkReal(*line, 0, range, "");
}

int64_t SectionReader::integer(std::string_view key, std::optional<int64_t> fallback, int64_t min,
                               int64_t max) {
  const ConfigLine* line = this->line(key);
  if (!line) {
    if (!fallback)
      throw InputError({text_.name, 0},
                       "missing required key '" + std::string(key) + "' (" + spec(key).hint() + ")");
    return *fallback;
  }
  expectCount(*line, 1);
  std::optional<int64_t> value = parseInt(line->values[0]);
  if (!value)
    throw InputError(line->where, "'" + line->key + "': '" + line->values[0] + "' is not an integer");
  if (*value < min || *value > max)
    throw InputError(line->where, "'" + line->key + "' = " + line->values[0] +
                                      " is out of range; it must be in [" + std::to_string(min) + ", " +
                                      std::to_string(max) + "]");
  return *value;
}

uint64_t SectionReader::unsignedInteger(std::string_view key, uint64_t fallback) {
  const ConfigLine* line = this->line(key);
  if (!line) return fallback;
  expectCount(*line, 1);
  std::optional<uint64_t> value = parseUInt(line->values[0]);
  if (!value)
    throw InputError(line->where,
                     "'" + line->key + "': '" + line->values[0] + "' is not a non-negative integer");
  return *value;
}

std::vector<double> SectionReader::reals(std::string_view key, size_t count,
                                         std::optional<std::vector<double>> fallback, Range range) {
  const ConfigLine* line = this->line(key);
  if (!line) {
    if (!fallback)
      throw InputError({text_.name, 0},
                       "missing required key '" + std::string(key) + "' (" + spec(key).hint() + ")");
    return *fallback;
  }
  expectCount(*line, count);
  std::vector<double> values;
  for (size_t i = 0; i < count; ++i)
    values.push_back(checkReal(*line, i, range, count > 1 ? "value " + std::to_string(i + 1) : ""));
  return values;
}

std::vector<double> SectionReader::realList(std::string_view key, Range range) {
  const ConfigLine* line = this->line(key);
  if (!line)
    throw InputError({text_.name, 0},
                     "missing required key '" + std::string(key) + "' (" + spec(key).hint() + ")");
  std::vector<double> values;
  for (size_t i = 0; i < line->values.size(); ++i)
    values.push_back(checkReal(*line, i, range, "value " + std::to_string(i + 1)));
  return values;
}

glm::dvec3 SectionReader::vec3(std::string_view key, glm::dvec3 fallback, Range range) {
  std::vector<double> v = reals(key, 3, std::vector<double>{fallback.x, fallback.y, fallback.z}, range);
  return {v[0], v[1], v[2]};
}

bool SectionReader::boolean(std::string_view key, bool fallback) {
  const ConfigLine* line = this->line(key);
  if (!line) return fallback;
  expectCount(*line, 1);
  std::string v = toLower(line->values[0]);
  if (v == "true" || v == "1" || v == "yes" || v == "on") return true;
  if (v == "false" || v == "0" || v == "no" || v == "off") return false;
  throw InputError(line->where,
                   "'" + line->key + "': '" + line->values[0] + "' is not a boolean; use true or false");
}

std::string SectionReader::word(std::string_view key, const std::string& fallback,
                                const std::vector<std::string>& choices) {
  const ConfigLine* line = this->line(key);
  if (!line) return fallback;
  expectCount(*line, 1);
  for (const std::string& choice : choices)
    if (toLower(choice) == toLower(line->values[0])) return choice;
  std::string all;
  for (const std::string& choice : choices) all += (all.empty() ? "" : ", ") + choice;
  throw InputError(line->where, "'" + line->key + "': '" + line->values[0] + "' is not one of " + all);
}

PathRef SectionReader::path(std::string_view key) {
  const ConfigLine* line = this->line(key);
  if (!line) return {};
  expectCount(*line, 1);
  std::filesystem::path p(line->values[0]);
  bool fromCommandLine = line->where.line == 0;
  if (p.is_relative()) p = (fromCommandLine ? std::filesystem::path() : text_.baseDir) / p;
  return PathRef{p.lexically_normal(), line->where};
}

std::vector<const ConfigLine*> SectionReader::lines(std::string_view key) {
  spec(key);
  std::vector<const ConfigLine*> found;
  for (size_t i = 0; i < text_.lines.size(); ++i) {
    if (canonicalKey(section_, text_.lines[i].key) != key) continue;
    used_[i] = true;
    found.push_back(&text_.lines[i]);
  }
  return found;
}

void SectionReader::finish() const {
  for (size_t i = 0; i < text_.lines.size(); ++i) {
    if (used_[i]) continue;
    const ConfigLine& line = text_.lines[i];
    if (canonicalKey(section_, line.key).empty())
      throw InputError(line.where, "unknown key '" + line.key + "' in " + section_.title +
                                       unknownKeyHint(section_, line.key));
    // A known key nobody read: the reader forgot it. Name it rather than ignore it.
    throw InputError(line.where, "key '" + line.key + "' is not used by this version of hairgen");
  }
}

}  // namespace hairgen
